"""A tiny stand-in world for the circuit tests: small frames, few states, short episodes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from neurocur.contexts.base import Episode, World
from neurocur.experiments import load_experiment


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
        self.mixing = {s: rng.uniform(-1.0, 1.0, size=(2, self.n_pixels)) / 4.0 for s in set(self.source_names)}
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
def circuits_dir():
    return Path(__file__).resolve().parents[2] / "neurocur" / "circuits"


@pytest.fixture(scope="session")
def small():
    """Overrides that make the CD-MISFA circuit fit the stand-in world."""
    return {"HPC.n_states": 20}


@pytest.fixture(scope="session")
def short_experiment(tmp_path_factory):
    """``short_experiment(name, steps)``: the shipped experiment ``"synthetic"`` or ``"icub"`` cut to
    ``steps`` frames per run, with a freeze that stores modules within a few thousand frames
    (``HPC.freeze = "episode_mean"``, threshold 1). The iCub data set (3 episodes) is simulated
    once per session into one cache; where it cannot be (no MuJoCo offscreen rendering), the
    test asking for it is skipped."""
    cache = tmp_path_factory.mktemp("icub")
    prepared: dict[str, str] = {}  # "icub" -> "" when simulated, else why it cannot be

    def load(name: str, steps: int):
        sets = ['HPC.freeze="episode_mean"', "HPC.threshold=1.0"]
        if name == "icub":
            sets += [f"world.cache_dir={json.dumps(str(cache))}", "world.n_episodes=3", "world.n_jobs=1"]
        experiment = load_experiment(name, steps=steps, sets=sets)
        if name == "icub":
            if name not in prepared:
                cond = experiment.conditions["curious"]
                try:
                    cond.world_class.prepare(cond.world_params)
                    prepared[name] = ""
                except Exception as exc:  # any GL or import failure means no iCub data set here
                    prepared[name] = f"the iCub data set cannot be simulated here: {exc}"
            if prepared[name]:
                pytest.skip(prepared[name])
        return experiment

    return load
