"""The analysis notebooks run end to end on small real results folders (neurocur run)."""

from __future__ import annotations

import sys
from pathlib import Path

import nbformat
import numpy as np
import pandas as pd
import pytest
from neuro_tables import results_of

from neurocur.analysis import (
    efficiency_per_run,
    engagement,
    event_locked_average,
    events,
    load,
    occupancy,
    source_specs,
    visits,
)
from neurocur.cli import main
from neurocur.tables import shipped_files

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "analysis" / "synthetic.ipynb"
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"


@pytest.fixture(scope="module")
def real_results(tmp_path_factory):
    """The curious and random-switching conditions of neurocur/experiments_data/synthetic.toml, 2 runs x 2e4 frames."""
    out = tmp_path_factory.mktemp("notebook") / "synthetic"
    argv = ["run", str(SYNTHETIC), "--runs", "2", "--steps", "20000", "--jobs", "1", "--out", str(out),
            "--condition", "curious", "--condition", "random_switching", "--no-progress"]
    assert main(argv) == 0
    return out


def test_notebook_executes(real_results, monkeypatch, execute_notebook):
    episodes, modules = load(real_results)
    assert set(episodes["condition"]) == {"curious", "random_switching"}
    assert episodes.groupby("condition")["step"].max().min() >= 19_900

    monkeypatch.setenv("NEUROCUR_RESULTS", str(real_results))  # the kernel inherits the environment
    outputs, text = execute_notebook(NOTEBOOK, timeout=120, extra_cells=["import sys\nprint(sys.executable)"])
    # the kernel is this interpreter (jupyter_client starts "python" as sys.executable)
    assert text.strip().splitlines()[-1] == sys.executable
    assert str(real_results) in text
    # the order table counts this folder's runs: "k/2" for each condition
    n_first = modules[modules["module"] == 0].groupby("condition")["source"].apply(lambda s: (s == "S-A").sum())
    assert "S-A first" in text
    for condition in ("curious", "random_switching"):
        assert f"{n_first.get(condition, 0)}/2" in text
    assert "needs the conditions" not in text  # the comparison ran
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) == 6  # Figures 4D-G, the order counts and the neuromodulator traces


NEUROMODULATORS = ROOT / "analysis" / "neuromodulators.ipynb"


def test_neuromodulators_notebook_executes(tmp_path, monkeypatch, execute_notebook):
    """analysis/neuromodulators.ipynb runs its experiments small (2 runs x 5000 frames, three gains) and
    shows every analysis; every shipped LC and VTA circuit is a condition of its results."""
    out = tmp_path / "neuromodulators"
    for key, value in {"RESULTS": str(out), "RUNS": "2", "STEPS": "5000", "GAINS": "0.5,2,8", "JOBS": "2"}.items():
        monkeypatch.setenv(f"NEUROCUR_NEURO_{key}", value)
    outputs, _ = execute_notebook(NEUROMODULATORS)
    episodes, _ = load(out / "models")
    models = {name for name in shipped_files("circuit") if name.startswith(("lc_", "vta_"))}
    assert set(episodes["condition"]) == {"curious", "random_switching", *models}
    assert episodes.groupby("condition")["run"].nunique().eq(2).all()
    swept, _ = load(out / "inverted_u")
    assert sorted(swept["LC.gain"].unique()) == [0.5, 2.0, 8.0]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) == 7  # occupancy, DA in the TV, efficiency, event-locked, tonic-phasic, Goldilocks, inverted U
    html = "".join(o.get("data", {}).get("text/html", "") for o in outputs)
    assert "interior_peak" in html and "frames_to_learn_all_censored" in html


def test_the_behaviour_analyses_agree_on_a_real_run(real_results):
    """The dwell, efficiency and event analyses of one real folder count the same frames and events."""
    episodes, modules = load(real_results)
    spec = source_specs(real_results)
    frames = episodes.groupby(["condition", "run"])["n_frames"].sum()
    engaged = engagement(episodes, spec).set_index(["condition", "run", "context_name"])
    assert engaged.groupby(["condition", "run"])["frames"].sum().equals(frames)
    assert np.allclose(engaged.groupby(["condition", "run"])["share"].sum(), 1.0)
    assert occupancy(episodes, 10_000, spec).groupby(["condition", "run"])["frames"].sum().equals(frames)
    table = visits(episodes, spec)
    assert table.groupby(["condition", "run"])["frames"].sum().equals(frames)
    runs = efficiency_per_run(results_of(episodes, modules, spec)).set_index(["condition", "run"])
    assert runs["n_steps"].equals(frames)
    assert runs["frames_unlearnable"].equals(engaged.xs("C5", level="context_name")["frames"])
    assert (runs["n_modules"] == modules.groupby(["condition", "run"]).size().reindex(runs.index, fill_value=0)).all()
    found = events(episodes).groupby(["condition", "run", "event"]).size()
    switches = found.xs("context_switch", level="event")
    assert switches.equals(table.groupby(["condition", "run"]).size() - 1)
    stored = found.xs("module_stored", level="event") if "module_stored" in found.index.get_level_values("event") \
        else pd.Series(dtype=int)
    assert stored.sum() == len(modules)
    locked = event_locked_average(episodes, "da", "context_switch", window=2)
    at_switch = locked[locked["lag"] == 0].set_index("condition")["n_events"]
    assert at_switch.equals(switches.groupby("condition").sum().rename("n_events"))


@pytest.mark.parametrize("name", ["synthetic.ipynb", "neuromodulators.ipynb"])
def test_the_notebooks_text_names_the_paired_tests_their_cells_compute(name):
    # compare() pairs by run by default (Wilcoxon signed-rank, McNemar exact); a notebook whose text
    # names the unpaired tests above such a cell describes another computation than it shows
    notebook = nbformat.read(ROOT / "analysis" / name, as_version=4)
    text = "\n".join(cell.source for cell in notebook.cells if cell.cell_type == "markdown")
    code = "\n".join(cell.source for cell in notebook.cells if cell.cell_type == "code")
    assert "paired=False" not in code
    assert "Mann–Whitney" not in text and "Fisher" not in text
