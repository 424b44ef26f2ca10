"""`neurocur run` on a canonical task prints the task's own statistics over runs, not the module-learning
summary, and writes them beside its figures as statistics.csv (docs/validation.md)."""

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.validation import over_runs, over_runs_text
from neurocur.cli import main


def test_over_runs_by_hand():
    per_run = pd.DataFrame({"condition": ["a", "a", "a", "b"], "run": [0, 1, 2, 0], "label": ["x"] * 4,
                            "hits": [0.5, 0.7, np.nan, 0.2], "d": [1.0, 2.0, 4.0, 3.0]})
    table = over_runs(per_run).set_index(["condition", "statistic"])
    assert list(table.index) == [("a", "hits"), ("a", "d"), ("b", "hits"), ("b", "d")]  # no run, no text column
    assert table.loc[("a", "hits"), "runs"] == 2 and table.loc[("a", "hits"), "mean"] == pytest.approx(0.6)
    assert table.loc[("a", "hits"), "sd"] == pytest.approx(np.sqrt(0.02))  # ddof 1: (0.1² + 0.1²) / 1
    assert table.loc[("a", "d"), ["mean", "min", "max"]].tolist() == pytest.approx([7 / 3, 1.0, 4.0])
    assert np.isnan(table.loc[("b", "d"), "sd"]) and table.loc[("b", "d"), "mean"] == 3.0
    text = over_runs_text(over_runs(per_run))
    assert "0.6 (0.5 to 0.7)" in text and "2.33 (1 to 4)" in text
    assert text.splitlines()[0].split() == ["condition", "a", "b"]


def test_over_runs_keeps_a_group_beyond_the_condition():
    per_run = pd.DataFrame({"condition": ["a"] * 4, "run": [0, 0, 1, 1], "block": [0, 1, 0, 1],
                            "reward": [1.0, 0.0, 0.8, 0.2]})
    table = over_runs(per_run, by=("condition", "block")).set_index(["block", "statistic"])
    assert table.loc[(0, "reward"), "mean"] == pytest.approx(0.9) and table.loc[(1, "reward"), "mean"] == pytest.approx(0.1)


@pytest.mark.parametrize("name, steps, rows", [
    ("gilzenrat2002", 40 * 300, ("burst_ratio", "hit_rate", "false_alarm_rate", "d_prime")),
    ("schultz1997", 60 * 25, ("r_cue_trial", "r_reward_trial", "omission_dip")),
    ("adaptive_gain_2005", 260 * 20, ("ne_tonic", "disengage")),
])
def test_a_canonical_task_prints_and_writes_its_own_statistics(name, steps, rows, tmp_path, capsys):
    out = tmp_path / name
    assert main(["run", name, "--runs", "2", "--steps", str(steps), "--jobs", "1", "--out", str(out),
                 "--no-progress"]) == 0
    printed = capsys.readouterr().out
    for row in rows:
        assert row in printed
    for row in ("modules per run", "S-A first", "exact"):  # the module-learning summary's rows
        assert row not in printed
    per_run = pd.read_csv(out / "figures" / "validation.csv")
    statistics = pd.read_csv(out / "figures" / "statistics.csv")
    by = ["condition", "block"] if "block" in per_run else ["condition"]
    for row in rows:
        means = per_run.groupby(by)[row].mean()  # the runs' mean, computed here from the per-run table
        got = statistics[statistics["statistic"] == row].set_index(by)["mean"]
        np.testing.assert_allclose(got.loc[means.index].to_numpy(), means.to_numpy(), rtol=1e-12)
        assert (statistics[statistics["statistic"] == row]["runs"] <= 2).all()
