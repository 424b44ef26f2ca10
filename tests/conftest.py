"""Shared by every test folder: where the shipped circuit files are, a tiny stand-in world (small
frames, few states, short episodes) for region and circuit tests, and executing a notebook."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurocur.contexts.base import Episode, World


@pytest.fixture(scope="session")
def circuits_dir():
    return Path(__file__).resolve().parents[1] / "neurocur" / "circuits"


class StandInWorld(World):
    """Contexts 0 and 1 show the same slow source (two sinusoids over the local clock),
    context 2 shows white noise. Each source is mixed into 6x6 frames by a random
    matrix drawn at reset; every context keeps its own local clock of ``n_states`` steps
    and a visit shows ``episode_len`` consecutive steps."""

    context_names = ("slow-1", "slow-2", "noise")
    source_names = ("S", "S", "N")
    frame_shape = (6, 6)

    def __init__(self, n_states: int = 20, episode_len: int = 20):
        super().__init__()
        self.n_states = n_states
        self.episode_len = episode_len

    def _reset(self) -> None:
        rng = self.np_random
        self.mixing = {s: rng.uniform(-1.0, 1.0, size=(2, self.n_pixels)) / 4.0 for s in sorted(set(self.source_names))}
        self.clock = np.zeros(self.n_contexts, dtype=np.int64)

    def _visit(self, context: int) -> Episode:
        t = (self.clock[context] + np.arange(self.episode_len)) % self.n_states
        self.clock[context] = (self.clock[context] + self.episode_len) % self.n_states
        source = self.source_names[context]
        if source == "N":
            src = self.np_random.uniform(-1.0, 1.0, size=(self.episode_len, 2))
        else:
            phase = 2 * np.pi * t / self.n_states
            src = np.column_stack([np.sin(phase), np.cos(3 * phase)])
        frames = np.clip(0.5 + src @ self.mixing[source], 0.0, 1.0)
        return Episode(frames=frames, states=t.astype(np.int64), context=context)


@pytest.fixture(scope="session")
def make_world():
    """The stand-in world class (call it with ``n_states``, ``episode_len``)."""
    return StandInWorld


@pytest.fixture(scope="session")
def small():
    """Overrides that make the CD-MISFA circuit fit the stand-in world."""
    return {"HPC.n_states": 20}


def _execute_notebook(path: Path, *, timeout: int = 300, extra_cells=()):
    """Execute the notebook at ``path`` in its folder (the kernel inherits the environment), with
    ``extra_cells`` (code) appended; a failing cell fails the test. Returns the outputs of its code
    cells and the text they printed."""
    import nbclient
    import nbformat

    nb = nbformat.read(path, as_version=4)
    nb.cells += [nbformat.v4.new_code_cell(code) for code in extra_cells]
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=timeout,
                                     resources={"metadata": {"path": str(path.parent)}})
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as error:  # pragma: no cover - shown on failure
        pytest.fail(f"notebook cell failed:\n{error}")
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    return outputs, "".join(o.get("text", "") for o in outputs if o.output_type == "stream")


@pytest.fixture(scope="session")
def execute_notebook():
    """``execute_notebook(path, *, timeout=300, extra_cells=())`` -> (cell outputs, printed text)."""
    return _execute_notebook

