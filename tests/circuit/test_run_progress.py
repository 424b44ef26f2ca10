"""Simulator.run's progress option: off (None, False) or a callable told the frames seen after each episode."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld


def _sim():
    return Circuit.from_toml("cd_misfa").build(SyntheticWorld(visit_length=30, frame_shape=(6, 5)), seed=1)


def test_progress_is_called_with_the_frames_seen_after_every_episode():
    seen = []
    sim = _sim().run(100, progress=seen.append)
    assert seen == [30, 60, 90, 120] == list(sim.episodes()["episode"].add(1) * 30)
    sim.run(30, progress=seen.append)
    assert seen[-1] == 150 == sim.n_frames


def test_progress_off_runs_the_same_episodes():
    quiet, off, told = _sim().run(90), _sim().run(90, progress=False), _sim().run(90, progress=lambda n: None)
    np.testing.assert_array_equal(quiet.episodes()["context"], off.episodes()["context"])
    np.testing.assert_array_equal(quiet.episodes()["context"], told.episodes()["context"])
    with pytest.raises(ValueError, match="progress must be None, False or a callable"):
        _sim().run(90, progress="yes")
