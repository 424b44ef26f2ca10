"""Trial tables (neurocur.fit.trials): the formats, the column mapping, 1-based codes only when told, missed
trials, and bad data refused in one line naming the file and the file's column."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.fit.trials import TRIAL_COLUMNS, read_trials, trials_from_table

OPTIONS = ("A", "B")


def _write(path, table, sep=","):
    if path.suffix == ".parquet":
        table.to_parquet(path)
    else:
        table.to_csv(path, sep=sep, index=False)
    return path


def _table(**columns):
    base = {"subject": ["x", "x", "x", "y", "y"], "trial": [1, 2, 3, 1, 2], "choice": [0, 1, 1, 1, 0],
            "outcome": [1.0, 0.0, 1.0, 0.0, 1.0]}
    return pd.DataFrame({**base, **columns})


@pytest.mark.parametrize("name,sep", [("t.csv", ","), ("t.tsv", "\t"), ("t.txt", "\t"), ("t.txt", ","),
                                      ("tab.csv", "\t"), ("t.parquet", None)])
def test_every_format_reads_the_same_trials(tmp_path, name, sep):
    found = read_trials(_write(tmp_path / name, _table(), sep), OPTIONS)
    assert [t.name for t in found] == ["x", "y"]
    np.testing.assert_array_equal(found[0].choices, [0, 1, 1])
    np.testing.assert_array_equal(found[1].outcomes, [0.0, 1.0])
    np.testing.assert_array_equal(found[0].trials, [1, 2, 3])


def test_the_column_mapping_names_and_one_based_codes(tmp_path):
    table = pd.DataFrame({"sid": ["x", "x", "x"], "t": [5, 6, 9], "family": [2, 1, 2], "correct": [1, 1, 0],
                          "rt": [0.5, 0.7, 0.6], "block": [1, 1, 2]})
    path = _write(tmp_path / "t.tsv", table, "\t")
    (found,) = read_trials(path, OPTIONS, columns={"subject": "sid", "trial": "t", "choice": "family",
                                                   "outcome": "correct"}, one_based=True)
    np.testing.assert_array_equal(found.choices, [1, 0, 1])
    np.testing.assert_array_equal(found.signals["rt"], [0.5, 0.7, 0.6])
    named = trials_from_table(_table(choice=["A", "B", "B", "B", "A"]), OPTIONS)
    np.testing.assert_array_equal(named[0].choices, [0, 1, 1])
    # codes stored as text are codes: 1-based ones are refused without the flag, read with it
    text = _table(choice=["1", "2", "2", "2", "1"])
    with pytest.raises(ConfigError, match="--one-based"):
        trials_from_table(text, OPTIONS)
    np.testing.assert_array_equal(trials_from_table(text, OPTIONS, one_based=True)[0].choices, [0, 1, 1])


def test_a_missed_trial_is_left_out_and_counted():
    table = _table(choice=[0, None, 1, 1, 0], outcome=[1.0, np.nan, 1.0, 0.0, 1.0])
    x, y = trials_from_table(table, OPTIONS)
    assert x.skipped == 1 and y.skipped == 0
    np.testing.assert_array_equal(x.trials, [1, 3])
    np.testing.assert_array_equal(x.choices, [0, 1])
    named = trials_from_table(_table(choice=["A", "", "B", "B", "A"]).replace("", None), OPTIONS)
    assert named[0].skipped == 1


def _refused(tmp_path, table, *, sep="\t", columns=None, one_based=False, name="t.tsv"):
    path = _write(tmp_path / name, table, sep)
    with pytest.raises(ConfigError) as info:
        read_trials(path, OPTIONS, columns=columns, one_based=one_based)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    return info.value


def test_one_based_codes_without_the_flag_are_refused(tmp_path):
    error = _refused(tmp_path, _table(choice=[1, 2, 2, 1, 2]).rename(columns={"choice": "family"}),
                     columns={"choice": "family"})
    assert error.key == "family" and "--one-based" in str(error)
    # the same codes with the flag are read
    assert len(read_trials(tmp_path / "t.tsv", OPTIONS, columns={"choice": "family"}, one_based=True)) == 2


@pytest.mark.parametrize("table,one_based,key,got", [
    (_table(choice=["A", "B", "C", "A", "B"]), False, "choice", "'C' in row 2"),  # an unknown option name
    (_table(choice=[0, 1, 3, 1, 0]), False, "choice", "3 in row 2"),  # a code out of range
    (_table(choice=[1, 2, 0, 1, 2]), True, "choice", "0 in row 2"),  # 0 is no 1-based code
    (_table(choice=[0, 1.5, 1, 1, 0]), False, "choice", "1.5 in row 1"),
    (_table().drop(columns="subject"), False, "subject", "none"),  # a missing subject column
    (_table().drop(columns="outcome"), False, "outcome", "none"),
    (_table(outcome=[1.0, "win", 1.0, 0.0, 1.0]), False, "outcome", "'win' in row 1"),
    (_table(trial=[1, 3, 2, 1, 2]), False, "trial", "trial 2 after trial 3"),
])
def test_bad_data_is_one_line_naming_file_and_column(tmp_path, table, one_based, key, got):
    error = _refused(tmp_path, table, one_based=one_based)
    assert error.key == key and got in error.got, str(error)


def test_a_mapped_column_that_is_missing_is_named(tmp_path):
    error = _refused(tmp_path, _table(), columns={"subject": "subjID"})
    assert error.key == "subjID" and "subject=subjID" in str(error)


def test_the_command_refuses_in_one_line_and_episode_experiments_refuse_trial_options(tmp_path, capsys):
    data = _write(tmp_path / "c.tsv", _table(choice=[1, 2, 2, 1, 2]), "\t")
    assert main(["fit", str(data), "--experiment", "bandit", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(data) in err and "'choice'" in err and "--one-based" in err
    assert main(["fit", str(data), "--experiment", "free_choice", "--fit", "LC.gain", "--bounds", "LC.gain=0:9",
                 "--one-based"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--one-based" in err and "options" in err
    assert main(["fit", str(data), "--experiment", "free_choice", "--bounds", "LC.gain=0:9"]) == 2
    assert "--fit" in capsys.readouterr().err  # free_choice declares no free parameters


def test_the_standard_columns_are_public():
    assert TRIAL_COLUMNS == ("subject", "trial", "choice", "outcome")


def test_a_link_a_fifo_and_latin1_text_are_refused_without_reading_through_them(tmp_path):
    """Trial tables go through the fit layer's one reader (neurocur.fit.files): no link followed, no FIFO opened
    for reading (it would block), bytes that are not UTF-8 named with their offset."""
    import os

    target = tmp_path / "target.tsv"
    target.write_text("subject\ttrial\tchoice\toutcome\ns\t0\t0\t1\n")
    (tmp_path / "link.tsv").symlink_to(target)
    with pytest.raises(ConfigError, match="symbolic link"):
        read_trials(tmp_path / "link.tsv", ["a", "b"])
    os.mkfifo(tmp_path / "pipe.tsv")
    with pytest.raises(ConfigError, match="a FIFO"):
        read_trials(tmp_path / "pipe.tsv", ["a", "b"])
    (tmp_path / "latin.tsv").write_bytes("subject\ttrial\tchoice\toutcome\ns\u00e9\t0\t0\t1\n".encode("latin-1"))
    with pytest.raises(ConfigError, match="UTF-8.*0xe9"):
        read_trials(tmp_path / "latin.tsv", ["a", "b"])
