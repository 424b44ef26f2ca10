"""The inferential Posner world with changing cue identity (Yu & Dayan 2005; docs/validation.md, section 4):
its frame layout, the validity of the relevant cue, the unsignalled changes of the relevant cue on a
schedule or with a hazard, and its one-line errors."""

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.contexts import build_world
from neurocur.contexts.posner import PosnerWorld, relevant_columns, target_column, validity_column


def _trials(world, n, seed):
    first, _ = world.reset(seed=seed)
    frames = np.concatenate([first.frames] + [world.step(0)[0].frames for _ in range(n - 1)])
    h = world.params.cues
    relevant = np.argmax(frames[:, relevant_columns(h)], axis=1)
    return frames[:, :h], frames[:, target_column(h)], relevant, frames[:, validity_column(h)]


def test_the_relevant_cue_predicts_the_target_with_its_validity_and_the_others_do_not():
    world = PosnerWorld(cues=4, validities=(0.8,), block_trials=10 ** 6)
    cues, target, relevant, validity = _trials(world, 20000, seed=3)
    assert set(np.unique(cues)) == {0.0, 1.0} and set(np.unique(target)) == {0.0, 1.0}
    assert len(np.unique(relevant)) == 1 and (validity == 0.8).all()
    agree = cues == target[:, None]
    mu = relevant[0]
    bound = 4 * np.sqrt(0.8 * 0.2 / 20000)  # 0.011: tells 0.8 from 0.78 or 0.82
    assert abs(agree[:, mu].mean() - 0.8) < bound
    for other in set(range(4)) - {mu}:
        assert abs(agree[:, other].mean() - 0.5) < 4 * np.sqrt(0.25 / 20000)
    assert abs(cues.mean() - 0.5) < 4 * np.sqrt(0.25 / 80000)


def test_the_relevant_cue_changes_unsignalled_every_block_and_the_validities_cycle():
    world = PosnerWorld(cues=5, validities=(0.9, 0.6, 0.7), block_trials=50)
    cues, _, relevant, validity = _trials(world, 400, seed=4)
    changes = np.flatnonzero(np.diff(relevant)) + 1
    np.testing.assert_array_equal(changes, np.arange(50, 400, 50))  # always to another cue
    np.testing.assert_allclose(validity, np.repeat([0.9, 0.6, 0.7, 0.9, 0.6, 0.7, 0.9, 0.6], 50))
    assert len(set(relevant[changes])) > 1
    again = _trials(PosnerWorld(cues=5, validities=(0.9, 0.6, 0.7), block_trials=50), 400, seed=4)
    np.testing.assert_array_equal(again[0], cues)


def test_with_a_change_probability_the_context_is_a_hidden_markov_chain():
    world = PosnerWorld(cues=3, validities=(0.9, 0.7), block_trials=10, change_probability=0.05)
    _, _, relevant, validity = _trials(world, 6000, seed=5)
    changed = np.diff(relevant) != 0
    # Binomial(5999, 0.05): mean 300, sd 16.9; blocks of 10 would give 599 changes
    assert abs(changed.sum() - 0.05 * 5999) < 4 * np.sqrt(5999 * 0.05 * 0.95)
    np.testing.assert_array_equal(np.diff(validity) != 0, changed)  # the validity changes with the cue
    lengths = np.diff(np.flatnonzero(np.concatenate([[True], changed, [True]])))
    assert lengths.mean() == pytest.approx(20, rel=0.15)  # geometric blocks, mean 1/q


def test_bad_settings_get_one_line_naming_the_key():
    with pytest.raises(ConfigError, match="validities"):
        PosnerWorld(validities=(0.9, 0.4))
    with pytest.raises(ConfigError, match="cues"):
        PosnerWorld(cues=1)
    with pytest.raises(ConfigError, match="change_probability"):
        PosnerWorld(change_probability=1.0)
    world = build_world({"type": "posner", "cues": 3})
    assert world.frame_shape == (1, 8) and world.n_pixels == 8
