"""analysis/fitting.ipynb runs end to end on small data."""

from __future__ import annotations

from pathlib import Path

NOTEBOOK = Path(__file__).resolve().parents[2] / "analysis" / "fitting.ipynb"


def test_fitting_notebook_executes(monkeypatch, execute_notebook):
    monkeypatch.setenv("NEUROCUR_FIT_DATASETS", "4")
    monkeypatch.setenv("NEUROCUR_FIT_EPISODES", "60")
    outputs, text = execute_notebook(NOTEBOOK)
    lines = text.splitlines()
    replayed = next(line for line in lines if line.startswith("replayed log-likelihood"))
    own = next(line for line in lines if line.startswith("the agent's own"))
    assert replayed.split()[-1] == own.split()[-1]  # replay = the agent's own log-probabilities
    assert "Bayesian omnibus risk" in text and "coverage" in text
    assert len([o for o in outputs if "image/png" in o.get("data", {})]) == 3
