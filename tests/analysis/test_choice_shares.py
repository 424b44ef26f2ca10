"""neurocur.analysis.stats.choice_shares on hand-made choice tables with answers worked by hand."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.choice_shares import (
    ordered_peaks,
    peak_bins,
    permutation_tests,
    share_array,
    share_change,
    share_summary,
)

OPTIONS = ("1D", "I1D", "2D", "R")


def table(sequences):
    """{subject: choices in order} as a tidy table, trials numbered from 1 (rows shuffled)."""
    rows = [{"subject": s, "trial": t + 1, "choice": c} for s, seq in sequences.items() for t, c in enumerate(seq)]
    return pd.DataFrame(rows).sample(frac=1.0, random_state=0)


def test_shares_per_bin_by_hand():
    # 10 choices in 5 bins of 2; subject b: 7 choices in 2 bins, floor(i*2/7): bins of 4 and 3
    trials = table({"a": ["1D", "1D", "1D", "R", "I1D", "R", "2D", "2D", "R", "R"],
                    "b": ["R", "R", "R", "1D", "2D", "2D", "2D"]})
    shares, subjects = share_array(trials[trials["subject"] == "a"], OPTIONS, n_bins=5)
    assert subjects == ["a"]
    assert shares[0].tolist() == [[1, 0, 0, 0], [0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 1, 0], [0, 0, 0, 1]]
    shares_b, _ = share_array(trials[trials["subject"] == "b"], OPTIONS, n_bins=2)
    assert shares_b[0].tolist() == [[0.25, 0, 0, 0.75], [0, 0, 1, 0]]


def test_bad_tables_are_refused():
    with pytest.raises(ValueError, match="'X'"):
        share_array(table({"a": ["1D", "X"]}), OPTIONS, n_bins=2)
    with pytest.raises(ValueError, match="at least 3"):
        share_array(table({"a": ["1D", "R"]}), OPTIONS, n_bins=3)
    with pytest.raises(ValueError, match="'trial'"):
        share_array(pd.DataFrame({"subject": [1], "choice": ["1D"]}), OPTIONS)


def test_peaks_ties_and_never_chosen():
    shares = np.array([[[0.6, 0.2, 0.2, 0.0],
                        [0.2, 0.6, 0.2, 0.0],
                        [0.2, 0.2, 0.6, 0.0],
                        [0.6, 0.2, 0.2, 0.0]]])
    peaks = peak_bins(shares)
    # 1D ties in bins 1 and 4 (mean 2.5); I1D peaks in 2; 2D in 3; R never chosen
    assert peaks[0, :3].tolist() == [2.5, 2.0, 3.0] and np.isnan(peaks[0, 3])
    assert np.isnan(ordered_peaks(peaks, [0, 1, 3])[0])
    assert ordered_peaks(peaks, [0, 1, 2])[0] == 0.0  # 2.5 < 2 fails
    assert ordered_peaks(peaks, [1, 2])[0] == 1.0
    assert ordered_peaks(np.array([[1.0, 1.0, 2.0]]), [0, 1, 2])[0] == 0.0  # strictly


def test_share_change_halves():
    shares = np.zeros((1, 5, 4))
    shares[0, :, 3] = [0.8, 0.6, 0.5, 0.2, 0.0]  # (0.2 + 0.0)/2 - (0.8 + 0.6)/2, the middle bin left out
    assert share_change(shares, 3)[0] == pytest.approx(-0.6, abs=1e-15)


def test_summary_mean_and_interval():
    shares = np.zeros((3, 2, 4))
    shares[:, 0, 0] = [0.2, 0.4, 0.9]
    shares[:, 1, 1] = 0.5
    summary = share_summary(shares, OPTIONS, n_boot=500)
    first = summary[(summary["bin"] == 1) & (summary["option"] == "1D")].iloc[0]
    assert first["mean"] == pytest.approx(0.5, abs=1e-15) and first["n"] == 3
    assert 0.2 <= first["ci_low"] < 0.5 < first["ci_high"] <= 0.9
    same = summary[(summary["bin"] == 2) & (summary["option"] == "I1D")].iloc[0]
    assert (same["ci_low"], same["ci_high"]) == (0.5, 0.5)


def ordered_subject():
    """Two bins: 1D and R fill the first, I1D and 2D the second... with 1D's peak before I1D's."""
    shares = np.zeros((2, 4))
    shares[0] = [0.5, 0.0, 0.0, 0.5]
    shares[1] = [0.0, 0.5, 0.5, 0.0]
    return shares


def test_permutation_null_by_hand():
    # Two bins, one shuffle of two equally likely: 1D before I1D (order [0, 1]) holds in one of the two,
    # and R's change is -1/2 in one and +1/2 in the other. Three such subjects: P(all three ordered) = 1/8,
    # P(mean R change <= -1/2) = 1/8; the opposite tails hold every shuffle (p = 1 exactly).
    shares = np.stack([ordered_subject()] * 3)
    tests = permutation_tests({"g": shares}, [0, 1], 3, n_permutations=8000, seed=5)
    peaks, change = tests.iloc[0], tests.iloc[1]
    assert (peaks["observed"], peaks["n"]) == (3.0, 3) and change["observed"] == -0.5
    for row in (peaks, change):
        assert row["p_value"] == pytest.approx(1 / 8, abs=0.015)  # Monte Carlo SE 0.0037
        assert row["p_opposite"] == 1.0
    assert peaks["null_mean"] == pytest.approx(1.5, abs=0.03) and change["null_mean"] == pytest.approx(0, abs=0.02)
    # the same seed gives the same table
    assert permutation_tests({"g": shares}, [0, 1], 3, n_permutations=8000, seed=5).equals(tests)


def test_holm_over_every_row():
    flat = np.full((4, 2, 4), 0.25)  # every shuffle the same: no order (ties), no change, p = 1
    tests = permutation_tests({"ordered": np.stack([ordered_subject()] * 3), "flat": flat}, [0, 1], 3,
                              n_permutations=2000, seed=1)
    assert tests["group"].tolist() == ["ordered", "ordered", "flat", "flat"]
    assert tests.loc[2:, "p_value"].tolist() == [1.0, 1.0] and tests.loc[2, "n"] == 4
    # Holm by hand: sorted p ascending, multiplied by 4, 3, 2, 1, running maximum, capped at 1
    p = tests["p_value"].to_numpy()
    order = np.argsort(p, kind="stable")
    adjusted = np.minimum(1.0, np.maximum.accumulate(p[order] * np.array([4, 3, 2, 1])))
    expected = np.empty(4)
    expected[order] = adjusted
    assert tests["p_holm"].to_numpy() == pytest.approx(expected, abs=1e-15)
    assert tests.loc[0, "p_holm"] == pytest.approx(4 * tests.loc[0, "p_value"], rel=0.2)
