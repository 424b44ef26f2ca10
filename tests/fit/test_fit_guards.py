"""What the fit commands refuse or warn about: each probe of a careful user, exit 2 in one line naming the file
and column (or a warning line and a flag in summary.json), on tiny free-choice tables."""

from __future__ import annotations

import json
import os
import shutil
import signal
import tomllib

import numpy as np
import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.experiments import load_experiment
from neurocur.fit.recovery import simulate

NAMES = ("easy", "medium", "hard", "impossible")
FIT = ["--experiment", "free_choice", "--condition", "learning_progress", "--fit", "LC.gain",
       "--bounds", "LC.gain=0:60", "--starts", "1"]


@pytest.fixture(scope="module")
def table():
    """Two data sets of 40 free choices of the learning-progress model, with the recorded error."""
    condition = load_experiment("free_choice").conditions["learning_progress"]
    parts = []
    for i in range(2):
        _, episodes = simulate(condition, {"LC.gain": 20.0}, 300 + i, 40, signal=("HPC", "error"))
        parts.append(pd.DataFrame({"dataset": f"s{i}", "episode": episodes["episode"],
                                   "context": [NAMES[c] for c in episodes["context"]],
                                   "decision": [NAMES[c] for c in episodes["next_context"]],
                                   "error": episodes["error"]}))
    return pd.concat(parts, ignore_index=True)


def _one_line_error(capsys, status: int, *words: str) -> str:
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err, err
    for word in words:
        assert word in err, (word, err)
    return err


def test_a_data_set_named_pooled_is_refused(tmp_path, table, capsys):
    data = tmp_path / "choices.csv"
    table.assign(dataset=table["dataset"].map({"s0": "pooled", "s1": "s1"})).to_csv(data, index=False)
    status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(tmp_path / "fit")])
    _one_line_error(capsys, status, str(data), "'dataset'", "'pooled'")
    assert not (tmp_path / "fit").exists()


def test_a_results_folder_of_another_experiment_or_world_is_refused(tmp_path, folder, capsys):
    status = main(["fit", str(folder), "--experiment", "goldilocks", "--fit", "LC.epsilon0",
                   "--out", str(tmp_path / "fit")])
    _one_line_error(capsys, status, str(folder / "config.toml"), "'goldilocks'", "'free_choice'")
    other = tmp_path / "other"
    shutil.copytree(folder, other)
    config = (other / "config.toml").read_text()
    (other / "config.toml").write_text(config.replace('"hard", "impossible"]', '"hard", "other"]'))
    assert tomllib.loads((other / "config.toml").read_text())["conditions"]["learning_progress"]["world"][
        "context_names"][3] == "other"
    status = main(["fit", str(other), *FIT, "--out", str(tmp_path / "fit")])
    _one_line_error(capsys, status, "conditions.learning_progress.world.context_names", "another world")
    assert main(["fit", str(folder), *FIT, "--out", str(tmp_path / "fit")]) == 0  # its own experiment: fitted


@pytest.mark.parametrize("bounds, words", [
    ("LC.gain=-100:-1", ["--bounds", "'LC.gain'", "a number >= 0", "-100"]),
    ("NOPE.x=0:1", ["--bounds", "'NOPE.x'", "a key no --fit names"]),
])
def test_bounds_outside_the_domain_or_of_no_fitted_key_are_refused(tmp_path, table, capsys, bounds, words):
    data = tmp_path / "choices.csv"
    table.to_csv(data, index=False)
    status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--bounds", bounds, "--out", str(tmp_path / "f")])
    _one_line_error(capsys, status, *words)
    status = main(["compare", str(data), "--experiment", "free_choice", "--models", "learning_progress", "random",
                   "--fit", "learning_progress:LC.gain", "--signal", "HPC=error", "--bounds", bounds,
                   "--out", str(tmp_path / "c")])
    _one_line_error(capsys, status, *words)
    assert not (tmp_path / "f").exists() and not (tmp_path / "c").exists()


@pytest.mark.parametrize("argv, message", [
    (["fit", "x.csv", *FIT, "--starts", "0"], "argument --starts: expected a number of optimiser starts of at least 1"),
    (["fit", "x.csv", *FIT, "--starts", "-3"], "argument --starts: expected a number of optimiser starts of at least 1"),
    (["recover", "free_choice", "--fit", "LC.gain", "--datasets", "1"], "at least 3 (Pearson r needs 3), got '1'"),
    (["recover", "free_choice", "--fit", "LC.gain", "--datasets", "0"], "at least 3 (Pearson r needs 3), got '0'"),
    (["sbi", "synthetic", "--prior", "HPC.threshold=0.1:0.5", "--simulations", "10", "--runs", "0"],
     "argument --runs: expected a number of runs of at least 1, got '0'"),
    (["sbi", "synthetic", "--prior", "HPC.threshold=0.1:0.5", "--simulations", "-4"],
     "argument --simulations: expected a number of simulations of at least 1, got '-4'"),
])
def test_counts_out_of_range_are_refused_by_the_parser(argv, message, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and message in err and "Traceback" not in err


def test_a_signal_column_without_signal_and_a_context_never_seen_warn(tmp_path, table, capsys):
    data = tmp_path / "choices.csv"
    table.to_csv(data, index=False)
    out = tmp_path / "fit"
    assert main(["fit", str(data), *FIT, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ignored_columns"] == ["error"] and "'error'" in err and "warning" in err
    assert any("--signal" in w for w in summary["warnings"])
    assert main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ignored_columns"] == [] and summary["warnings"] == [] and "warning" not in capsys.readouterr().err
    # two of the four contexts: easy and medium, alternating
    two = pd.DataFrame({"dataset": "s", "episode": range(30), "context": [NAMES[i % 2] for i in range(30)],
                        "decision": [NAMES[(i + 1) % 2] for i in range(30)]})
    two.to_csv(data, index=False)
    assert main(["fit", str(data), *FIT, "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["unseen_contexts"] == ["hard", "impossible"]
    err = capsys.readouterr().err
    assert "'hard', 'impossible'" in err and "all 4 contexts" in err


def test_a_fifo_and_a_symbolic_link_are_refused_without_reading_them(tmp_path, table, capsys):
    real = tmp_path / "real.csv"
    table.to_csv(real, index=False)
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    status = main(["fit", str(link), *FIT, "--signal", "HPC=error", "--out", str(tmp_path / "fit")])
    _one_line_error(capsys, status, str(link), "symbolic link")
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)

    def stuck(*_):
        raise AssertionError("reading the FIFO blocked")

    old = signal.signal(signal.SIGALRM, stuck)
    signal.alarm(20)
    try:
        status = main(["fit", str(fifo), *FIT, "--out", str(tmp_path / "fit")])
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    _one_line_error(capsys, status, str(fifo), "a FIFO")
    assert not (tmp_path / "fit").exists()


@pytest.mark.parametrize("value, words", [
    (np.inf, ["'error'", "finite numbers", "inf"]),
    (1e308, ["'error'", "finite numbers", "1e+308"]),
    ("abc", ["'error'", "finite numbers", "'abc'"]),
])
def test_a_signal_that_is_not_a_finite_number_is_named(tmp_path, table, capsys, value, words):
    data = tmp_path / "choices.csv"
    bad = table.astype({"error": object})
    bad.loc[7, "error"] = value
    bad.to_csv(data, index=False)
    status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(tmp_path / "fit")])
    _one_line_error(capsys, status, str(data), "row 7", *words)


@pytest.mark.parametrize("content, words", [
    (b"", ["a table with a header row", "an empty file"]),
    ("dataset,episode,context,decision\ns\u00e9,0,easy,easy\n".encode("latin-1"), ["UTF-8", "0xe9"]),
])
def test_an_empty_or_latin1_file_is_named(tmp_path, capsys, content, words):
    data = tmp_path / "choices.csv"
    data.write_bytes(content)
    status = main(["fit", str(data), *FIT, "--out", str(tmp_path / "fit")])
    _one_line_error(capsys, status, str(data), *words)
    for command in (["sbi", "free_choice", "--prior", "LC.gain=1:2", "--simulations", "2", "--data", str(data)],
                    ["compare", str(data), "--experiment", "free_choice", "--models", "random"]):
        _one_line_error(capsys, main([*command, "--out", str(tmp_path / "x")]), str(data), *words)
    assert not (tmp_path / "x").exists()


def test_cells_a_spreadsheet_would_run_are_escaped_and_numbers_kept(tmp_path, table, capsys):
    names = {"s0": "=HYPERLINK(\"http://x\",\"y\")", "s1": "-3"}
    data = tmp_path / "choices.csv"
    table.assign(dataset=table["dataset"].map(names)).to_csv(data, index=False)
    out = tmp_path / "fit"
    assert main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(out)]) == 0
    fit = pd.read_csv(out / "fit.csv", dtype={"dataset": str})
    assert list(fit["dataset"]) == ["'=HYPERLINK(\"http://x\",\"y\")", "-3", "pooled"]
    assert (out / "fit.csv").read_text().splitlines()[2].startswith("-3,LC.gain,")  # a number stays a number
    compare = tmp_path / "compare"
    assert main(["compare", str(data), "--experiment", "free_choice", "--models", "learning_progress", "random",
                 "--fit", "learning_progress:LC.gain", "--bounds", "LC.gain=0:60", "--starts", "1", "--no-loo",
                 "--signal", "HPC=error", "--out", str(compare)]) == 0
    cells = pd.read_csv(compare / "compare.csv", dtype={"dataset": str})
    assert sorted(set(cells["dataset"])) == ["'=HYPERLINK(\"http://x\",\"y\")", "-3"]
    assert (cells["loglik"] < 0).all()  # negative numbers stay numbers
    from neurocur.fit.outdir import spreadsheet_safe

    safe = spreadsheet_safe(pd.DataFrame({"a": ["+1+2", "@x", "\tx", "\rx", "-x", "-1.5e3", "ok"], "b": -1.0},
                                         index=pd.Index(["=i", "j", "k", "l", "m", "n", "o"])))
    assert list(safe["a"]) == ["'+1+2", "'@x", "'\tx", "'\rx", "'-x", "-1.5e3", "ok"]
    assert list(safe["b"]) == [-1.0] * 7 and list(safe.index)[:2] == ["'=i", "j"]
