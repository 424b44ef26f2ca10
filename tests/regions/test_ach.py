"""ACh as expected uncertainty (Yu & Dayan 2005; docs/regions.md, ``ach.expected_uncertainty``): Y1-Y2 in
closed form over hand-made trials, the restart from the NE region's support after a switch, the drugs on
the released level, and ACh against 1 - validity after a block of constant validity."""

import numpy as np
import pytest
from posner_trials import NO_SUPPORT, H, trial

from neurocur.contexts.posner import PosnerWorld, target_column
from neurocur.regions.ach import ExpectedUncertaintyACh, believed_validity
from neurocur.regions.pharmacology import Scale


def _ach(**params):
    ach = ExpectedUncertaintyACh("ACh", **params)
    ach.bind(PosnerWorld(cues=H))
    ach.reset(np.random.default_rng(0))
    return ach



def test_ach_is_one_minus_the_beta_posterior_mean_of_the_validity():
    """Y1-Y2 by hand: after t trials on cue 1 of which k were valid, ACh = 1 - (k + a) / (t + a + b)."""
    valid = np.array([1, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1], dtype=bool)
    a, b = 2.0, 0.5
    ach = _ach(prior_valid=a, prior_invalid=b)
    released = []
    for _t, v in enumerate(valid):
        cues = np.array([0.0, 1.0, 0.0])
        episode = trial(cues, 1.0 if v else 0.0)
        released.append(ach.step(episode)[0])
        ach.learn(episode, 1, False, NO_SUPPORT)
    k = np.concatenate([[0], np.cumsum(valid)[:-1]])
    expected = 1.0 - (k + a) / (np.arange(len(valid)) + a + b)
    np.testing.assert_allclose(released, expected, rtol=0, atol=1e-12)
    assert expected[-1] == pytest.approx(1 - (7 + 2) / (11 + 2.5))


def test_a_switch_restarts_the_counts_from_the_new_cues_support():
    ach = _ach()
    for _ in range(30):
        episode = trial(np.array([1.0, 0.0, 0.0]), 1.0)
        ach.step(episode)
        ach.learn(episode, 0, False, NO_SUPPORT)
    assert ach.step(trial(np.zeros(3), 0.0))[0] == pytest.approx(1 - 31 / 32)
    ach.learn(trial(np.zeros(3), 1.0), 0, True, np.array([7, 12]))
    assert ach.step(trial(np.zeros(3), 0.0))[0] == pytest.approx(1 - 8 / 14, abs=1e-12)


def test_a_drug_acts_on_the_released_level_only():
    ach = _ach()
    ach.drugs = (Scale(factor=0.5),)
    episode = trial(np.array([1.0, 0.0, 0.0]), 0.0)
    for _ in range(3):
        level = ach.step(episode)[0]
        ach.learn(episode, 0, False, NO_SUPPORT)
    assert level == pytest.approx(0.5 * (1 - 1 / 4)) and ach.gamma_star == pytest.approx(1 / 5)
    assert ach.record()[:2] == (pytest.approx(0.375), pytest.approx(0.25))
    assert believed_validity(0.7) == 0.5 and believed_validity(-0.2) == 1.0 and believed_validity(0.25) == 0.75


@pytest.mark.parametrize("validity", [0.7, 0.9])
def test_after_a_block_of_constant_validity_ach_is_one_minus_the_validity(validity):
    """Attending the relevant cue through 5000 trials of one validity: ACh is the closed form of the
    trials' own counts and lies within 4 binomial sd (0.026 at 0.7) of 1 - validity."""
    world = PosnerWorld(cues=H, validities=(validity,), block_trials=10 ** 6)
    episode, _ = world.reset(seed=11)
    mu = int(np.argmax(episode.frames[0, H + 1:2 * H + 1]))
    ach, valid = _ach(), 0
    for _t in range(5000):
        ach.step(episode)
        ach.learn(episode, mu, False, NO_SUPPORT)
        valid += int(episode.frames[0, mu] == episode.frames[0, target_column(H)])
        episode = world.step(0)[0]
    level = ach.step(episode)[0]
    assert level == pytest.approx(1 - (valid + 1) / (5000 + 2), abs=1e-12)
    assert abs(level - (1 - validity)) < 4 * np.sqrt(validity * (1 - validity) / 5000)
    assert ach.record()[2] == validity


def test_the_posner_regions_refuse_another_world_in_one_line():
    from neurocur.contexts.conditioning import ConditioningWorld
    from neurocur.regions.ne_uncertainty import UnexpectedUncertaintyNE
    from neurocur.regions.posner import PosnerDecision

    for region in (ExpectedUncertaintyACh("ACh"), UnexpectedUncertaintyNE("NE"), PosnerDecision("decision")):
        with pytest.raises(ValueError, match=f"^{region.name}: needs the frames of a posner world.*ConditioningWorld"):
            region.bind(ConditioningWorld())
