"""The statistics of the Posner task (Yu & Dayan 2005; :mod:`neurocur.analysis.stats.posner`) on a
hand-made episodes table whose blocks, switches and reaction times are known."""

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.posner import posner_by_validity, posner_per_run, trials_to_adopt, with_blocks


def _run():
    """Two blocks of 8 trials: validity 0.9 with cue 0 relevant, then 0.6 with cue 2. The observer
    attends cue 0 throughout block 1 and for the first 3 trials of block 2, switches on trial 10 and
    attends cue 2 from trial 11. Valid trials take 2 samples, invalid ones 5 (block 1) or 3 (block 2)."""
    n = 16
    valid = np.array([1, 1, 1, 0, 1, 1, 1, 1, 1, 0, 1, 1, 0, 1, 0, 1], dtype=bool)
    block2 = np.arange(n) >= 8
    rt = np.where(valid, 2, np.where(block2, 3, 5))
    attended = np.where(np.arange(n) <= 10, 0, 2)
    return pd.DataFrame({
        "condition": "c", "run": 0, "episode": np.arange(n), "validity": np.where(block2, 0.6, 0.9),
        "relevant": np.where(block2, 2, 0), "changed": np.arange(n) == 8, "attended": attended,
        "switched": np.arange(n) == 10, "valid": valid, "rt": rt, "correct": valid | (np.arange(n) % 2 == 0),
        "ach": np.where(block2, 0.45, 0.12), "ne": np.where(np.arange(n) == 10, 0.8, 0.05),
        "prior": np.where(valid, 0.75, 0.25),
    })


def test_blocks_positions_and_the_trials_to_adopt_a_new_cue():
    ep = with_blocks(_run())
    np.testing.assert_array_equal(ep["block"], [0] * 8 + [1] * 8)
    np.testing.assert_array_equal(ep["position"], list(range(8)) * 2)
    np.testing.assert_array_equal(ep["late"], ([False] * 4 + [True] * 4) * 2)
    np.testing.assert_array_equal(trials_to_adopt(ep), [3.0])  # trials 8, 9, 10 on the old cue
    never = ep.assign(on_cue=ep["block"] == 0)
    np.testing.assert_array_equal(trials_to_adopt(never), [8.0])  # censored at the block's length


def test_per_run_and_per_validity_by_hand():
    row = posner_per_run(_run()).iloc[0]
    # late trials: 4-7 (all valid, rt 2) and 12-15 (valid 13, 15: rt 2; invalid 12, 14: rt 3)
    assert row["validity_effect"] == pytest.approx(3 - 2)
    assert row["switches"] == pytest.approx(1000 / 16) and row["false_switches"] == 0.0
    assert row["trials_to_adopt"] == 3.0 and row["changes"] == 1
    assert row["on_cue"] == pytest.approx(13 / 16)  # off the cue on trials 8, 9, 10 only
    assert row["ne_after_change"] == pytest.approx((7 * 0.05 + 0.8) / 8)
    assert row["prediction_score"] == pytest.approx((12 * np.log2(0.75) + 4 * np.log2(0.25)) / 16)
    by = posner_by_validity(_run()).set_index("validity")
    assert np.isnan(by.loc[0.9, "validity_effect"])  # no invalid late trial in block 1
    assert by.loc[0.6, "validity_effect"] == pytest.approx(1.0)
    assert by.loc[0.6, "ach"] == pytest.approx(0.45) and by.loc[0.6, "expected_ach"] == pytest.approx(0.4)
    assert by.loc[0.6, "accuracy_effect"] == pytest.approx(1.0 - 1.0)  # invalid 12 and 14 are even: correct
