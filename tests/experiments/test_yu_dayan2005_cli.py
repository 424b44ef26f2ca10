"""``neurocur run yu_dayan2005`` prints the task's own statistics (Yu & Dayan 2005), not the module-learning
summary, and writes them as CSV beside its figure (docs/validation.md, section 4)."""

from pathlib import Path

import pandas as pd
import pytest

from neurocur.analysis.results import Results
from neurocur.analysis.stats.posner import posner_per_run
from neurocur.cli import main


def test_run_prints_and_writes_the_tasks_statistics(tmp_path, capsys):
    out = tmp_path / "yd"
    rc = main(["run", "yu_dayan2005", "--runs", "2", "--steps", "600", "--jobs", "1", "--out", str(out),
               "--condition", "control", "--condition", "ne_depleted", "--no-progress"])
    printed = capsys.readouterr().out
    assert rc == 0 and f"results: {out}" in printed
    assert "S-A first" not in printed and "modules per run" not in printed
    figures = out / "figures"
    assert {p.name for p in figures.iterdir()} == {"validation.png", "validation.csv", "validation_by_validity.csv",
                                                   "index.csv", "statistics.csv"}
    assert pd.read_csv(figures / "index.csv")["file"].tolist() == ["validation.png"]
    table = pd.read_csv(figures / "validation.csv")
    expected = posner_per_run(Results.load(out).episodes)
    assert list(table["condition"]) == ["control", "control", "ne_depleted", "ne_depleted"]  # the file's order
    merged = table.merge(expected, on=["condition", "run"], suffixes=("", "_expected"))
    assert len(merged) == 4
    for column in ("validity_effect", "switches", "trials_to_adopt", "prediction_score"):
        assert merged[column].to_numpy() == pytest.approx(merged[f"{column}_expected"].to_numpy(), rel=1e-9)
    mean = table.groupby("condition")["switches"].mean()
    statistics = pd.read_csv(figures / "statistics.csv").set_index(["condition", "statistic"])
    line = next(line for line in printed.splitlines() if line.startswith("switches"))
    for condition in ("control", "ne_depleted"):
        assert statistics.loc[(condition, "switches"), "mean"] == pytest.approx(mean[condition], rel=1e-12)
        assert f"{mean[condition]:.3g}" in line.split()
    assert Path(figures / "validation.png").stat().st_size > 10_000
