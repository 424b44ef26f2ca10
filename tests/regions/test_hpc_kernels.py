"""HPC's compiled stored-error bookkeeping equals its numpy transcription to the bit."""

from __future__ import annotations

import numpy as np

from neurocur.regions._hpc_kernels import store_errors


def _numpy_store(row, prev, gated, states, err, known):
    previous = row[states]  # each frame's state's error before this episode
    both = known & ~np.isnan(previous)
    progress = float((previous[both] - err[both]).mean()) if both.any() else np.nan
    visited = states[known]
    prev[visited] = row[visited]
    row[visited] = err[known]
    missing = np.isnan(row)
    n_missing, m = np.count_nonzero(missing), len(row)
    if n_missing == m:
        mean = total = np.nan
    elif n_missing:
        mean, total = float(row[~missing].sum()) / (m - n_missing), np.nan
    else:
        total = float(row.sum())
        mean = total / m
    complete = not (missing & ~gated).any()
    kept, before = row[~missing], prev[~missing]
    drift = np.inf
    if not np.isnan(before).any() and kept.sum() < before.sum():
        now = float(kept.sum())
        drift = now / len(kept) / (1.0 - now / float(before.sum()))
    return mean, total, complete, drift, progress


def _same(a, b):
    return (np.isnan(a) and np.isnan(b)) or a == b


def test_store_errors_equals_numpy():
    rng = np.random.default_rng(0)
    finite = progressed = 0
    for m in (1, 7, 130, 1000):
        history = np.full((2, m), np.nan)  # drift_ratios = 1: this visit's errors and the previous visit's
        row, prev = history
        gated = rng.random(m) < 0.05
        row_ref, prev_ref = row.copy(), prev.copy()
        for visit in range(60):
            T = int(rng.integers(1, 2 * m + 2))  # longer than an epoch: states repeat within the episode
            states = (int(rng.integers(m)) + np.arange(T)) % m
            err = rng.random(T) * 10.0 ** rng.uniform(-3, 1) * np.exp(-visit / 10)  # errors that shrink
            known = rng.random(T) < 0.9
            got = store_errors(history, gated, states, err, known)
            ref = _numpy_store(row_ref, prev_ref, gated, states, err, known)
            np.testing.assert_array_equal(row, row_ref)
            np.testing.assert_array_equal(prev, prev_ref)
            assert got[2] == ref[2] and all(_same(g, r) for g, r in zip(got, ref)), (m, visit, got, ref)
            finite += bool(np.isfinite(got[3]) and np.isfinite(got[1]))
            progressed += bool(np.isfinite(got[4]))
    assert finite > 10 and progressed > 100  # the complete, shrinking case and the progress were reached
