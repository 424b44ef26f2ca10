"""Shared by the circuit tests: the shipped experiments cut short."""

from __future__ import annotations

import json

import pytest

from neurocur.experiments import load_experiment


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
