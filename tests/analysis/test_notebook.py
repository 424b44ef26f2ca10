"""The analysis notebook runs end to end on a small results folder."""

from __future__ import annotations

import sys
from pathlib import Path

import nbclient
import nbformat
import pytest

NOTEBOOK = Path(__file__).resolve().parents[2] / "analysis" / "synthetic.ipynb"


def test_notebook_executes(results_dir, monkeypatch):
    monkeypatch.setenv("NEUROCUR_RESULTS", str(results_dir))  # the kernel inherits the environment
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell("import sys\nprint(sys.executable)"))
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=120,
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as error:  # pragma: no cover - shown on failure
        pytest.fail(f"notebook cell failed:\n{error}")
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    # the kernel is this interpreter (jupyter_client starts "python" as sys.executable)
    assert text.strip().splitlines()[-1] == sys.executable
    assert str(results_dir) in text
    assert "S-A first" in text and "4/4" in text
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) == 6  # Figures 4D-G, the order counts and the neuromodulator traces
