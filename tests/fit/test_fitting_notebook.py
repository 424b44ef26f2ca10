"""analysis/fitting.ipynb runs end to end on small data."""

from __future__ import annotations

from pathlib import Path

import nbclient
import nbformat
import pytest

NOTEBOOK = Path(__file__).resolve().parents[2] / "analysis" / "fitting.ipynb"


def test_fitting_notebook_executes(monkeypatch):
    monkeypatch.setenv("NEUROCUR_FIT_DATASETS", "4")
    monkeypatch.setenv("NEUROCUR_FIT_EPISODES", "60")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=300,
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as error:  # pragma: no cover - shown on failure
        pytest.fail(f"notebook cell failed:\n{error}")
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    lines = text.splitlines()
    replayed = next(line for line in lines if line.startswith("replayed log-likelihood"))
    own = next(line for line in lines if line.startswith("the agent's own"))
    assert replayed.split()[-1] == own.split()[-1]  # replay = the agent's own log-probabilities
    assert "Bayesian omnibus risk" in text and "coverage" in text
    assert len([o for o in outputs if "image/png" in o.get("data", {})]) == 2
