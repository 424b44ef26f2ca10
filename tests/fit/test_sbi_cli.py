"""neurocur sbi on a tiny problem: its files and columns, a second run that resumes and repeats, a bad prior."""

from __future__ import annotations

import pandas as pd
import pytest

from neurocur.cli import main


def test_sbi_writes_its_tables_resumes_and_repeats(tmp_path, monkeypatch):
    pytest.importorskip("sbi")
    monkeypatch.chdir(tmp_path)  # sbi's default tracker would write its logs here
    out = tmp_path / "sbi"
    argv = ["sbi", "synthetic", "--condition", "curious", "--prior", "HPC.threshold=0.1:0.5", "--simulations", "4",
            "--runs", "2", "--steps", "500", "--test", "3", "--epochs", "3", "--jobs", "1", "--seed", "5",
            "--data", str(tmp_path / "data"), "--out", str(out)]
    assert main(["run", "synthetic", "--condition", "curious", "--runs", "2", "--steps", "500", "--jobs", "1",
                 "--out", str(tmp_path / "data")]) == 0
    assert main(argv) == 0
    runs = sorted((out / "sbi_training").glob("d*/runs/*/run-*"))
    tests = sorted((out / "sbi_test").glob("t*/runs/*/run-*"))
    assert len(runs) == 4 and len(tests) == 3 and len({p.parent.name for p in runs}) == 2
    posterior = pd.read_csv(out / "sbi.csv")
    assert list(posterior.columns) == ["dataset", "param", "estimate", "ci_low", "ci_high"]
    assert list(posterior["dataset"]) == ["curious/0", "curious/1"]
    assert ((0.1 <= posterior["ci_low"]) & (posterior["ci_low"] <= posterior["estimate"])
            & (posterior["estimate"] <= posterior["ci_high"]) & (posterior["ci_high"] <= 0.5)).all()
    recovery = pd.read_csv(out / "sbi_recovery.csv")
    assert list(recovery.columns) == ["dataset", "param", "true", "estimate", "ci_low", "ci_high"]
    assert list(recovery["dataset"]) == ["t00", "t01", "t02"] and recovery["true"].between(0.1, 0.5).all()
    summary = pd.read_csv(out / "sbi_recovery_summary.csv")
    assert list(summary.columns) == ["param", "n", "r", "bias", "rmse", "coverage"] and summary.loc[0, "n"] == 3
    assert (out / "sbi_recovery.png").stat().st_size > 0
    stamps = {p: p.stat().st_mtime_ns for p in runs + tests}
    assert main(argv) == 0  # every run is there: nothing is simulated again, and the same seed samples the same
    assert {p: p.stat().st_mtime_ns for p in runs + tests} == stamps
    pd.testing.assert_frame_equal(pd.read_csv(out / "sbi_recovery.csv"), recovery)
    pd.testing.assert_frame_equal(pd.read_csv(out / "sbi.csv"), posterior)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data", "sbi"]  # nothing outside --out


def test_a_bad_prior_exits_2_with_one_line(tmp_path, capsys):
    status = main(["sbi", "synthetic", "--prior", "HPC.threshold=0.5:0.1", "--simulations", "4",
                   "--out", str(tmp_path / "sbi")])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err and "--prior" in err and "'HPC.threshold=0.5:0.1'" in err
    assert not (tmp_path / "sbi").exists()
