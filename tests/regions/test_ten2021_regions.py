"""ten2021.utility (neurocur/regions/ten2021.py): each trial's utilities are the weighted PC, LP and play counts
of neurocur.fit.ten2021_utilities on a hand-made session, raw or rescaled by min-max over the scored trials; the
forced phase and the unscored first free choice are given (probability 1); a live world draws the forced blocks."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.contexts.options import OptionsParams, OptionsWorld
from neurocur.fit.ten2021_utilities import activity_signals, minmax
from neurocur.regions.ten2021 import ActivityUtility, UtilityParams

OPTIONS = OptionsParams(options=("1D", "I1D", "2D", "R"), p_reward=(0.9, 0.82, 0.66, 0.5))
#: the forced blocks of tests/fit/test_ten2021_utilities.py, in the order 2, 0, 3, 1: at the first free choice
#: PC = 5/15, 1, 8/15, 10/15 and LP = 5/9, 0, 1/18, 5/9 (worked there by hand)
FORCED = {0: [0] * 10 + [1] * 5, 1: [1] * 15, 2: [1, 0] * 7 + [1], 3: [1] * 10 + [0] * 5}
ORDER = (2, 0, 3, 1)


def session(n_free=40, seed=3):
    rng = np.random.default_rng(seed)
    choices = [k for k in ORDER for _ in range(15)] + list(rng.integers(0, 4, n_free))
    outcomes = [o for k in ORDER for o in FORCED[k]] + list((rng.random(n_free) < 0.7).astype(float))
    return np.array(choices, dtype=np.int64), np.array(outcomes)


def utilities(choices, outcomes, **params):
    """The region's output before every trial of the session, stepped as the circuit steps it."""
    region = ActivityUtility("PFC", params=UtilityParams(**params))
    region.bind(OptionsWorld(OPTIONS).recorded(choices, outcomes))
    region.reset(np.random.default_rng(0))
    out, previous = [], (None, None)
    for c, r in zip(choices, outcomes):
        out.append(region.step(*previous)[0])
        previous = (int(c), float(r))
    return np.array(out)


@pytest.mark.parametrize("weight,signal", [("pc", "pc"), ("lp", "lp"), ("plays", "plays")])
def test_raw_signals_equal_the_utilities_module(weight, signal):
    choices, outcomes = session()
    got = utilities(choices, outcomes, **{weight: 1.0}, rescale=False, unscored=0)
    expected = activity_signals(choices, outcomes)[signal]
    np.testing.assert_allclose(got[60:], expected[60:], rtol=0, atol=1e-15)
    np.testing.assert_allclose(utilities(choices, outcomes, **{weight: -2.5}, rescale=False, unscored=0)[60:],
                               -2.5 * expected[60:], rtol=0, atol=1e-14)


def test_the_first_free_choice_sees_the_forced_phase():
    choices, outcomes = session()
    assert utilities(choices, outcomes, pc=1.0, rescale=False, unscored=0)[60] == pytest.approx(
        [5 / 15, 1.0, 8 / 15, 10 / 15], abs=1e-15)
    assert utilities(choices, outcomes, lp=1.0, rescale=False, unscored=0)[60] == pytest.approx(
        [5 / 9, 0.0, 1 / 18, 5 / 9], abs=1e-15)
    assert utilities(choices, outcomes, plays=1.0, rescale=False, unscored=0)[60].tolist() == [15, 15, 15, 15]


def test_the_forced_phase_and_the_unscored_choice_are_given():
    choices, outcomes = session()
    got = utilities(choices, outcomes, pc=1.0, lp=-1.0)
    for t in range(61):  # 60 forced trials and the first free choice (unscored = 1)
        assert got[t, choices[t]] == 0.0 and np.isneginf(np.delete(got[t], choices[t])).all(), t
    assert np.isfinite(got[61:]).all()
    assert np.isfinite(utilities(choices, outcomes, pc=1.0, unscored=0)[60]).all()


def test_rescaled_per_participant_over_the_scored_trials():
    choices, outcomes = session()
    signals = activity_signals(choices, outcomes)
    scored = slice(61, None)
    x = {name: minmax(signals[name][scored].astype(float)) for name in ("pc", "lp", "plays")}
    got = utilities(choices, outcomes, pc=2.0, lp=-3.0, plays=0.5)[scored]
    np.testing.assert_allclose(got, 2.0 * x["pc"] - 3.0 * x["lp"] + 0.5 * x["plays"], rtol=0, atol=1e-13)
    # the range is the scored trials': a range over every trial (forced included) gives other utilities
    whole = minmax(signals["plays"].astype(float))[scored]
    assert np.abs(utilities(choices, outcomes, plays=1.0)[scored] - whole).max() > 0.1
    # the unscored first free choice is outside the range: 1D correct, then I1D only; PC's minimum is 1D's 5/15
    # before the first free choice and 6/15 after it, so the scored range is [6/15, 1]
    choices = np.r_[choices[:60], 0, [1] * 20]
    outcomes = np.r_[outcomes[:60], 1.0, [1.0] * 20]
    got = utilities(choices, outcomes, pc=1.0)[61]
    assert got == pytest.approx([0.0, 1.0, (8 / 15 - 6 / 15) / (9 / 15), (10 / 15 - 6 / 15) / (9 / 15)], abs=1e-14)


def test_a_live_agent_computes_the_same_signals_trial_by_trial():
    """Live, the region learns each outcome as it comes (window_signals per trial); in a replay it reads the
    session's table: both equal the utilities module's on the same sequence."""
    region = ActivityUtility("PFC", params=UtilityParams(pc=1.0, lp=-2.0, plays=0.25, rescale=False, unscored=0))
    region.bind(OptionsWorld(OPTIONS))
    region.reset(np.random.default_rng(11))
    order = [region.imposed(15 * b) for b in range(4)]
    rng = np.random.default_rng(12)
    choices = np.array([k for k in order for _ in range(15)] + list(rng.integers(0, 4, 50)), dtype=np.int64)
    outcomes = (rng.random(len(choices)) < 0.6).astype(float)
    got, previous = [], (None, None)
    for c, r in zip(choices, outcomes):
        got.append(region.step(*previous)[0])
        previous = (int(c), float(r))
    signals = activity_signals(choices, outcomes)
    expected = signals["pc"] - 2.0 * signals["lp"] + 0.25 * signals["plays"]
    np.testing.assert_allclose(np.array(got)[60:], expected[60:], rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.array(got)[60:], utilities(choices, outcomes, pc=1.0, lp=-2.0, plays=0.25,
                                                             rescale=False, unscored=0)[60:], rtol=0, atol=1e-14)


def test_a_live_world_draws_the_forced_blocks_and_needs_raw_signals():
    region = ActivityUtility("PFC", params=UtilityParams(pc=1.0, rescale=False, unscored=0))
    region.bind(OptionsWorld(OPTIONS))
    region.reset(np.random.default_rng(7))
    imposed = [region.imposed(t) for t in range(61)]
    blocks = [imposed[15 * b:15 * (b + 1)] for b in range(4)]
    assert all(len(set(b)) == 1 for b in blocks) and sorted(b[0] for b in blocks) == [0, 1, 2, 3]
    assert imposed[60] is None
    for params in ({"rescale": True, "unscored": 0}, {"rescale": False, "unscored": 1}):
        with pytest.raises(ValueError, match="needs a recorded session"):
            ActivityUtility("PFC", params=UtilityParams(**params)).bind(OptionsWorld(OPTIONS))


def test_a_session_without_the_forced_phase_is_refused():
    choices, outcomes = session()
    with pytest.raises(ValueError, match="forced phase"):
        utilities(choices[15:], outcomes[15:], pc=1.0)
    with pytest.raises(ValueError, match="forced phase"):
        utilities(choices[:61], outcomes[:61], pc=1.0)  # no scored free choice after the unscored one
