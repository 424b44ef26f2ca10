"""neurocur.fit.ten2021_utilities: each trial's PC, LP and play count of every activity before
the choice, on hand-made sequences with the answers worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.fit.ten2021_utilities import activity_signals, minmax

#: 15 forced outcomes per activity, the paper's familiarisation, played in blocks 0, 1, 2, 3
FORCED = {0: [0] * 10 + [1] * 5,  # PC 5/15; first 10: 0, last 9: 5/9 -> LP 5/9
          1: [1] * 15,  # PC 1, LP 0
          2: [1, 0] * 7 + [1],  # PC 8/15; first 10: 1/2, last 9 (positions 6..14): 5/9 -> LP 1/18
          3: [1] * 10 + [0] * 5}  # PC 10/15; first 10: 1, last 9: 4/9 -> LP 5/9 (absolute: signed would be -5/9)


def forced_then(free):
    choices = [k for k in range(4) for _ in range(15)] + [c for c, _ in free]
    outcomes = [o for k in range(4) for o in FORCED[k]] + [o for _, o in free]
    return np.array(choices), np.array(outcomes)


def test_the_forced_phase_fills_every_window():
    signals = activity_signals(*forced_then([(0, 1), (3, 0)]))
    first_free = 60
    assert signals["pc"][first_free] == pytest.approx([5 / 15, 1.0, 8 / 15, 10 / 15], abs=1e-15)
    assert signals["lp"][first_free] == pytest.approx([5 / 9, 0.0, 1 / 18, 5 / 9], abs=1e-15)
    assert signals["plays"][first_free].tolist() == [15, 15, 15, 15]
    # after one more correct 1D trial: window [0]*9 + [1]*6; first 10: 1/10, last 9: 6/9
    assert signals["pc"][61] == pytest.approx([6 / 15, 1.0, 8 / 15, 10 / 15], abs=1e-15)
    assert signals["lp"][61, 0] == pytest.approx(6 / 9 - 1 / 10, abs=1e-15)
    assert signals["plays"][61].tolist() == [16, 15, 15, 15]


def test_nan_until_the_window_is_full_and_no_look_ahead():
    choices, outcomes = forced_then([])
    signals = activity_signals(choices, outcomes)
    # trial 45 opens activity 3's block: activities 0-2 have 15 trials, activity 3 none
    assert np.isfinite(signals["pc"][45, :3]).all() and np.isnan(signals["pc"][45, 3])
    # trial 59 is activity 3's 15th: before its choice only 14 are known
    assert np.isnan(signals["lp"][59, 3]) and signals["plays"][59, 3] == 14
    # changing trial t's outcome changes nothing at or before t
    flipped = outcomes.copy()
    flipped[59] = 1 - flipped[59]
    assert np.array_equal(activity_signals(choices, flipped)["pc"][:60], signals["pc"][:60], equal_nan=True)


def test_a_short_window_by_hand():
    # window 3, early 2, late 2; activity 0's outcomes 1, 0, 0, 1 at trials 0, 2, 3, 5
    choices = [0, 1, 0, 0, 1, 0, 0]
    outcomes = [1, 1, 0, 0, 0, 1, 1]
    signals = activity_signals(choices, outcomes, n_activities=2, window=3, early=2, late=2)
    pc, lp = signals["pc"][:, 0], signals["lp"][:, 0]
    assert np.isnan(pc[:4]).all()
    assert pc[4] == pytest.approx(1 / 3) and lp[4] == pytest.approx(abs(0.0 - 0.5))  # [1, 0, 0]
    assert pc[6] == pytest.approx(1 / 3) and lp[6] == pytest.approx(abs(0.5 - 0.0))  # [0, 0, 1]
    assert np.isnan(signals["pc"][:, 1]).all()  # activity 1 played twice only


def test_bad_sequences_are_refused():
    with pytest.raises(ValueError, match="same length"):
        activity_signals([0, 1], [1])
    with pytest.raises(ValueError, match="integers 0 .. 3"):
        activity_signals([0, 4], [1, 0])
    with pytest.raises(ValueError, match="between 0 and 1"):
        activity_signals([0, 1], [1, 2])
    with pytest.raises(ValueError, match="early"):
        activity_signals([0], [1], early=16)


def test_minmax_over_every_activity_and_trial():
    assert minmax([[1.0, 3.0], [5.0, 9.0]]).tolist() == [[0.0, 0.25], [0.5, 1.0]]
    assert minmax([2.0, 2.0]).tolist() == [0.0, 0.0]
    out = minmax([np.nan, 1.0, 3.0])
    assert np.isnan(out[0]) and out[1:].tolist() == [0.0, 1.0]
