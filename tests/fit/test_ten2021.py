"""neurocur.fit.ten2021: the posted files of Ten et al. 2021 as trial tables, on hand-made files
in the same columns (never the real data), and the paper's response-bias exclusion."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd
import pytest

from neurocur.config import ConfigError
from neurocur.fit.ten2021 import COLUMNS, free_play, paper_exclusions, read_ten2021, read_ten2021_groups, response_bias

#: participant 0's family -> category (activity): Bear plays 2D, Bunny R, GreenMonster 1D, Squid I1D
MAPPING = {1: 3, 2: 4, 3: 1, 4: 2}


def rows(sid, trials, mapping=MAPPING, condition=0):
    """The posted columns for one participant: ``trials`` is a list of (stage, family, response, correct)."""
    out = []
    for i, (stage, family, response, correct) in enumerate(trials):
        out.append({"sid": sid, "trial": i + 1, "condition": condition, "stage": stage, "blockTrial": 0,
                    "family": family, "D1": 1, "D2": 2, "category": mapping[family], "choice": response,
                    "correct": correct, "switch": 0, "rt": 1000 + i})
    return out


def write(path, all_rows, columns=COLUMNS):
    pd.DataFrame(all_rows)[list(columns)].to_csv(path, index=False)
    return path


def test_conversion_of_hand_made_rows(tmp_path):
    trials = [(0, 1, 5, 1), (0, 2, 6, 0), (1, 3, 1, 1), (1, 4, 2, 0), (2, 1, 5, 1)]
    path = write(tmp_path / "main_strat.csv", rows(7, trials, condition=1))
    table = read_ten2021(path)
    assert list(table.columns[:5]) == ["subject", "trial", "choice", "outcome", "rt"]
    assert list(table["subject"]) == ["strat-7"] * 5
    assert list(table["trial"]) == [1, 2, 3, 4, 5]
    # Bear -> category 3 = 2D, Bunny -> 4 = R, GreenMonster -> 1 = 1D, Squid -> 2 = I1D
    assert list(table["choice"]) == ["2D", "R", "1D", "I1D", "2D"]
    assert list(table["outcome"]) == [1, 0, 1, 0, 1]
    assert list(table["stage"]) == ["forced", "forced", "free", "free", "test"]
    assert list(table["response"]) == [5, 6, 1, 2, 5]
    assert set(table["group"]) == {"strat"} and set(table["condition"]) == {1}
    assert list(table["rt"]) == [1000.0, 1001.0, 1002.0, 1003.0, 1004.0]


def test_the_group_comes_from_the_file_name_or_the_argument(tmp_path):
    path = write(tmp_path / "trials.csv", rows(0, [(0, 1, 1, 1)]))
    with pytest.raises(ConfigError, match="group"):
        read_ten2021(path)
    assert set(read_ten2021(path, "free")["subject"]) == {"free-0"}
    with pytest.raises(ConfigError, match="group"):
        read_ten2021(path, "IG")


def test_a_missing_column_names_the_file_and_the_column(tmp_path):
    path = write(tmp_path / "main_free.csv", rows(0, [(0, 1, 1, 1)]), [c for c in COLUMNS if c != "correct"])
    with pytest.raises(ConfigError, match=r"main_free\.csv: key 'correct'"):
        read_ten2021(path)


@pytest.mark.parametrize("column, value", [("correct", "yes"), ("correct", "2"), ("category", "5"), ("rt", "1.5"),
                                           ("stage", "")])
def test_a_bad_value_names_its_column(tmp_path, column, value):
    table = pd.DataFrame(rows(0, [(0, 1, 1, 1), (1, 2, 1, 0)]))[list(COLUMNS)].astype(str)
    table.loc[1, column] = value
    path = tmp_path / "main_free.csv"
    table.to_csv(path, index=False)
    with pytest.raises(ConfigError, match=f"key '{column}'") as err:
        read_ten2021(path)
    assert "\n" not in str(err.value)


def test_a_family_that_changes_activity_or_trials_out_of_order_are_refused(tmp_path):
    bad = rows(0, [(0, 1, 1, 1), (1, 1, 1, 1)])
    bad[1]["category"] = 2
    with pytest.raises(ConfigError, match="key 'category'"):
        read_ten2021(write(tmp_path / "main_free.csv", bad))
    gap = rows(0, [(0, 1, 1, 1), (1, 1, 1, 1)])
    gap[1]["trial"] = 3
    with pytest.raises(ConfigError, match="key 'trial'"):
        read_ten2021(write(tmp_path / "main_free.csv", gap))
    back = rows(0, [(1, 1, 1, 1), (0, 1, 1, 1)])
    with pytest.raises(ConfigError, match="key 'stage'"):
        read_ten2021(write(tmp_path / "main_free.csv", back))


def test_a_symbolic_link_or_a_fifo_is_refused(tmp_path):
    real = write(tmp_path / "real_free.csv", rows(0, [(0, 1, 1, 1)]))
    link = tmp_path / "main_free.csv"
    link.symlink_to(real)
    with pytest.raises(ConfigError, match="symbolic link"):
        read_ten2021(link)
    fifo = tmp_path / "fifo_free.csv"
    os.mkfifo(fifo)
    with pytest.raises(ConfigError, match="FIFO"):
        read_ten2021(fifo)
    with pytest.raises(ConfigError, match="no such file"):
        read_ten2021(tmp_path / "absent_free.csv")


def biased(sid, same_per_family):
    """Two trials per family; in a family listed in ``same_per_family`` both answers are that
    family's own food (bias 1 there), elsewhere the two answers differ (bias 1/2)."""
    forced = [(0, family, 2 * family - 1, 1) for family in (1, 2, 3, 4)]
    free = [(1, family, 2 * family - (family in same_per_family), 0) for family in (1, 2, 3, 4)]
    return rows(sid, forced + free)


def test_response_bias_is_per_family_then_averaged(tmp_path):
    # participant 1 answers each family with one food, a different one per family: bias 1, not 1/4
    path = write(tmp_path / "main_free.csv", biased(0, ()) + biased(1, (1, 2, 3, 4)) + biased(2, (1,)))
    bias = response_bias(read_ten2021(path))
    assert bias.to_dict() == {"free-0": 0.5, "free-1": 1.0, "free-2": 0.625}


def test_the_paper_exclusion_on_hand_made_participants(tmp_path):
    # six at bias 1/2 and one at 1: mean 4/7, sample SD sqrt(1/28), threshold 4/7 + 2 sqrt(1/28) = 0.9494
    # (the population SD would give 0.9213; a bias of 15/16 would tell them apart, the threshold does)
    free = [r for sid in range(4) for r in biased(sid, ())]
    strat = [r for sid in range(2) for r in biased(sid, ())] + biased(2, (1, 2, 3, 4))
    kept, report = read_ten2021_groups(write(tmp_path / "main_free.csv", free),
                                       write(tmp_path / "main_strat.csv", strat))
    assert report["threshold"].iloc[0] == pytest.approx(4 / 7 + 2 * np.sqrt(1 / 28), abs=1e-12)
    assert list(report.loc[report["excluded"], "subject"]) == ["strat-2"]
    assert sorted(kept["subject"].unique()) == ["free-0", "free-1", "free-2", "free-3", "strat-0", "strat-1"]
    everyone, report_all = read_ten2021_groups(tmp_path / "main_free.csv", tmp_path / "main_strat.csv", exclude=False)
    assert everyone["subject"].nunique() == 7 and report_all.equals(report)
    # within one group alone the same participant is still excluded, by that group's own threshold
    _, alone = paper_exclusions(read_ten2021(tmp_path / "main_strat.csv"))
    assert alone["threshold"].iloc[0] == pytest.approx(2 / 3 + 2 * np.sqrt(1 / 12), abs=1e-12)
    assert not alone["excluded"].any()


def test_free_play_keeps_the_first_free_trials(tmp_path):
    trials = [(0, 1, 1, 1)] * 2 + [(1, 3, 1, 1)] * 3 + [(1, 4, 1, 0)] * 2
    path = write(tmp_path / "main_free.csv", rows(0, trials) + rows(1, [(0, 1, 1, 1)] + [(1, 2, 1, 1)] * 4))
    free = free_play(read_ten2021(path), n_trials=4)
    assert list(free["free_trial"]) == [1, 2, 3, 4] * 2
    assert list(free.loc[free["subject"] == "free-0", "choice"]) == ["1D", "1D", "1D", "I1D"]
    assert list(free.loc[free["subject"] == "free-0", "trial"]) == [3, 4, 5, 6]
    with pytest.raises(ValueError, match="free-1"):
        free_play(read_ten2021(path), n_trials=5)


def curriculum(sid, free_families):
    """15 forced trials per family, then one free choice per entry of ``free_families``."""
    forced = [(0, family, 1, 1) for family in (1, 2, 3, 4) for _ in range(15)]
    return rows(sid, forced + [(1, family, 1, 1) for family in free_families])


def test_the_study_command_on_hand_made_files(tmp_path, capsys):
    from neurocur.fit.ten2021 import main

    # GreenMonster = 1D, Squid = I1D, Bear = 2D, Bunny = R (MAPPING): 1D, then I1D, then 2D, R at the start
    ordered = [2] * 25 + [3] * 75 + [4] * 75 + [1] * 75
    reverse = [1] * 100 + [4] * 75 + [3] * 50 + [2] * 25
    free = write(tmp_path / "main_free.csv", curriculum(0, ordered) + curriculum(1, ordered))
    strat = write(tmp_path / "main_strat.csv", curriculum(0, reverse) + curriculum(1, reverse))
    out = tmp_path / "out"
    assert main([str(free), str(strat), "--out", str(out), "--permutations", "200", "--keep-all"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["participants.csv", "peaks.csv", "peaks.png", "shares.csv",
                                                     "shares.png", "tests.csv"]
    peaks = pd.read_csv(out / "peaks.csv").set_index("subject")
    # free: R fills bin 1, 1D bins 2-4 (tie, mean 3), I1D bins 5-7 (6), 2D bins 8-10 (9); R falls by 1/5
    assert peaks.loc["free-0", ["peak_R", "peak_1D", "peak_I1D", "peak_2D"]].tolist() == [1.0, 3.0, 6.0, 9.0]
    assert peaks.loc["free-0", "ordered"] == 1.0 and peaks.loc["free-0", "change_R"] == pytest.approx(-0.2)
    assert peaks.loc["strat-1", "ordered"] == 0.0
    shares = pd.read_csv(out / "shares.csv")
    first = shares[(shares["group"] == "free") & (shares["bin"] == 1)].set_index("option")["mean"]
    assert first.to_dict() == {"1D": 0.0, "I1D": 0.0, "2D": 0.0, "R": 1.0}
    tests = pd.read_csv(out / "tests.csv")
    assert tests[["group", "statistic"]].values.tolist() == [["free", "ordered peaks"], ["free", "change in share"],
                                                            ["strat", "ordered peaks"], ["strat", "change in share"]]
    assert tests["observed"].tolist() == pytest.approx([2.0, -0.2, 0.0, 0.2])
    assert "free 2 -> 2, strat 2 -> 2" in capsys.readouterr().out


def test_the_study_command_refuses_a_bad_file_in_one_line(tmp_path, capsys):
    from neurocur.fit.ten2021 import main

    free = write(tmp_path / "main_free.csv", rows(0, [(0, 1, 1, 1)]), [c for c in COLUMNS if c != "rt"])
    strat = write(tmp_path / "main_strat.csv", rows(0, [(0, 1, 1, 1)]))
    assert main([str(free), str(strat), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "main_free.csv: key 'rt'" in err
    assert not (tmp_path / "out").exists()
