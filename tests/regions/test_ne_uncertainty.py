"""NE as unexpected uncertainty (Yu & Dayan 2005; docs/regions.md, ``ne.unexpected_uncertainty``): the
belief update Y3-Y4 against an independent odds recursion, the switch rule Y6 (NE > ACh / (0.5 + ACh)) on
the trial it first holds, a threshold that rises with ACh, the choice of the new cue and a drug on NE."""

import numpy as np
from posner_trials import H, trial

from neurocur.contexts.posner import PosnerWorld
from neurocur.regions.ne_uncertainty import UnexpectedUncertaintyNE
from neurocur.regions.pharmacology import Scale


def _ne(cue=0, **params):
    ne = UnexpectedUncertaintyNE("NE", **params)
    ne.bind(PosnerWorld(cues=H))
    ne.reset(np.random.default_rng(0))
    ne.cue = cue
    return ne


def _odds_recursion(valid, gamma, q, belief):
    """Y3-Y4 in odds form: prior odds (1 - q) l / (1 - (1 - q) l), times the likelihood ratio L / (1/2)."""
    out = []
    for v in valid:
        prior = (1 - q) * belief
        odds = prior / (1 - prior) * (gamma if v else 1 - gamma) / 0.5
        belief = odds / (1 + odds)
        out.append(1 - belief)
    return np.array(out)


def test_ne_is_one_minus_the_posterior_that_the_attended_cue_is_still_relevant():
    valid = [1, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1]
    ne = _ne(change_probability=0.02, reset_belief=0.95)
    levels = []
    for v in valid:
        out = ne.step(trial(np.array([1.0, 0.0, 0.0]), 1.0 if v else 0.0), 0.2)
        levels.append(out[0])
        assert out[1] == 0 and not out[2]
    np.testing.assert_allclose(levels, _odds_recursion(valid, 0.8, 0.02, 0.95), rtol=0, atol=1e-12)
    assert levels[3] > 2.5 * levels[2]  # an invalid trial after valid ones: NE jumps, below 0.2 / 0.7


def _trials_to_switch(ach):
    """After 40 valid trials, invalid ones: the region switches on exactly the trial where the
    recursion's NE first exceeds ACh / (0.5 + ACh), and not before; returns that trial."""
    valid = [1] * 40 + [0] * 30
    ne_by_hand = _odds_recursion(valid, 1 - ach, 0.01, 0.9)
    expected = int(np.argmax(ne_by_hand > ach / (0.5 + ach)))
    ne = _ne(change_probability=0.01, reset_belief=0.9)
    switched = [ne.step(trial(np.array([1.0, 0.0, 0.0]), float(v)), ach)[2] for v in valid[:expected + 1]]
    assert switched == [False] * expected + [True]
    return expected


def test_the_switch_comes_on_the_first_trial_ne_exceeds_ach_over_half_plus_ach_and_later_for_more_ach():
    """The more uncertain the cue is known to be, the more invalid trials it takes to switch."""
    needed = [_trials_to_switch(a) - 40 for a in (0.05, 0.2, 0.35)]
    assert needed[0] < needed[1] < needed[2] and needed[0] == 0  # at ACh 0.05, on the first invalid trial


def test_a_switch_adopts_the_cue_that_agreed_most_over_the_memory_and_reports_its_support():
    ne = _ne(cue=0, memory=4, change_probability=0.01)
    # over the four trials cue 2 agrees with the target on 4, cue 0 on 3 (not the last), cue 1 on 2
    rows = [([1.0, 0.0, 1.0], 1.0), ([0.0, 0.0, 0.0], 0.0), ([1.0, 0.0, 1.0], 1.0), ([1.0, 0.0, 0.0], 0.0)]
    for cues, target in rows[:-1]:
        out = ne.step(trial(np.array(cues), target), 0.3)
        assert not out[2] and out[1] == 0
        np.testing.assert_array_equal(out[3], [0, 0])
    ne.belief = 0.3  # one invalid trial now puts NE over 0.3 / 0.8
    out = ne.step(trial(np.array(rows[-1][0]), rows[-1][1]), 0.3)
    assert out[2] and out[1] == 0 and ne.cue == 2  # attended during the trial: 0; from the next: 2
    np.testing.assert_array_equal(out[3], [4, 4])
    assert ne.belief == 0.9


def test_depleted_ne_misses_the_change():
    ne = _ne(change_probability=0.01)
    ne.drugs = (Scale(factor=0.0),)
    outs = [ne.step(trial(np.array([1.0, 0.0, 0.0]), 0.0), 0.1) for _ in range(50)]
    assert not any(o[2] for o in outs) and all(o[0] == 0.0 for o in outs) and ne.belief < 1e-6
