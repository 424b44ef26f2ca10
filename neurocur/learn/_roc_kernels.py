"""Compiled per-sample loops of :class:`neurocur.learn.roc.ROCBank` (Algorithm 3, eq 10).

All arrays are the bank's own dense storage and are updated in place:
``centers`` (n_states, max_clusters, n_features), ``weights`` (n_states, max_clusters),
``n_clusters`` (n_states,) and ``latest`` (n_states,), the slot holding each state's
latest sample (-1 before the state's first sample). Inputs are validated by the caller.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _sq_dist(U, i, V, j):
    """||U[i] - V[j]||² without temporaries."""
    d2 = 0.0
    for f in range(U.shape[1]):
        diff = U[i, f] - V[j, f]
        d2 += diff * diff
    return d2


@njit(cache=True)
def roc_partial_fit(centers, weights, n_clusters, latest, states, Y, amnesic, inv_two_width_sq):
    """Run Algorithm 3 (ROC-Amnesic) once per row of ``Y``, on the clusterer of ``states[t]``.

    RESPONSE(y, c) = exp(-||y - c||² · inv_two_width_sq). Ties (equal distances) go to
    the lowest slot; the merged pair (g, d) has g < d, so the merge is kept in slot g and
    the latest sample takes slot d. A merge of two weight-0 clusters (0/0 in line 9)
    takes their plain mean, the limit of equal weights.
    """
    n_features = Y.shape[1]
    xi = centers.shape[1]
    keep = 1.0 - amnesic
    for t in range(Y.shape[0]):
        s = states[t]
        C = centers[s]
        a = weights[s]
        n = n_clusters[s]
        if n < xi:  # lines 2-3: a new cluster at y with weight 0
            for f in range(n_features):
                C[n, f] = Y[t, f]
            a[n] = 0.0
            n_clusters[s] = n + 1
            latest[s] = n
            continue
        # line 5: the winner has the largest response, i.e. the nearest centre
        win = 0
        best = np.inf
        for j in range(xi):
            d2 = _sq_dist(Y, t, C, j)
            if d2 < best:
                best = d2
                win = j
        # lines 6-7: move the winner, then grow its weight by its (new) response
        step = 1.0 / (a[win] + 1.0)
        d2 = 0.0
        for f in range(n_features):
            C[win, f] += (Y[t, f] - C[win, f]) * step
            diff = Y[t, f] - C[win, f]
            d2 += diff * diff
        a[win] += np.exp(-d2 * inv_two_width_sq)
        # line 8: the two closest centres (largest mutual response)
        g = 0
        d = 1
        best = np.inf
        for i in range(xi):
            for j in range(i + 1, xi):
                d2 = _sq_dist(C, i, C, j)
                if d2 < best:
                    best = d2
                    g = i
                    d = j
        # lines 9-10: weighted merge into g
        total = a[g] + a[d]
        if total > 0.0:
            wg = a[g] / total
            wd = a[d] / total
        else:
            wg = 0.5
            wd = 0.5
        for f in range(n_features):
            C[g, f] = C[g, f] * wg + C[d, f] * wd
        a[g] = total
        # lines 11-12: the latest input becomes a new cluster with weight 0 in slot d
        for f in range(n_features):
            C[d, f] = Y[t, f]
        a[d] = 0.0
        latest[s] = d
        # lines 13-15: every weight leaks
        for j in range(xi):
            a[j] *= keep


@njit(cache=True)
def roc_error(centers, n_clusters, states, Y, err, known):
    """Eq 10 per row: ``err[t] = min_j ||Y[t] - c_j||`` over the clusters of ``states[t]``.

    ``known[t]`` is False (and ``err[t]`` 0.0) when that state has no cluster yet.
    """
    for t in range(Y.shape[0]):
        s = states[t]
        n = n_clusters[s]
        if n == 0:
            err[t] = 0.0
            known[t] = False
            continue
        C = centers[s]
        best = np.inf
        for j in range(n):
            d2 = _sq_dist(Y, t, C, j)
            if d2 < best:
                best = d2
        err[t] = np.sqrt(best)
        known[t] = True


@njit(cache=True)
def _block_sum(a, lo, n):
    """One leaf of :func:`pairwise_sum`: ``n <= 128`` values summed as numpy does."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    m = n - n % 8
    for i in range(lo + 8, lo + m, 8):
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for i in range(lo + m, lo + n):
        res += a[i]
    return res


@njit(cache=True)
def pairwise_sum(a, lo, n):
    """``a[lo:lo + n].sum()`` in numpy's order, so bit-identical to numpy's ``sum`` of a contiguous
    1-d array: blocks of at most 128 values summed by eight accumulators; a longer range is
    split at half its length (rounded down to a multiple of 8) and the halves' sums added.
    The recursion runs on an explicit stack (numba cannot cache recursive functions)."""
    if n <= 128:
        return _block_sum(a, lo, n)
    todo_lo = np.empty(128, np.int64)  # (lo, n) to sum, or n = -1: add the two sums on top of ``done``
    todo_n = np.empty(128, np.int64)
    done = np.empty(64)
    top, k = 1, 0
    todo_lo[0], todo_n[0] = lo, n
    while top:
        top -= 1
        lo, n = todo_lo[top], todo_n[top]
        if n == -1:
            k -= 1
            done[k - 1] += done[k]
        elif n <= 128:
            done[k] = _block_sum(a, lo, n)
            k += 1
        else:
            n2 = n // 2
            n2 -= n2 % 8
            todo_lo[top], todo_n[top] = 0, -1
            todo_lo[top + 1], todo_n[top + 1] = lo + n2, n - n2
            todo_lo[top + 2], todo_n[top + 2] = lo, n2
            top += 3
    return done[0]


@njit(cache=True)
def spread(Y):
    """``sqrt(mean_t ||Y[t] - mean(Y)||²)`` in numpy's order of operations (the column means
    summed row by row, or pairwise for a single column; each row's squares and the mean over
    rows pairwise)."""
    T, J = Y.shape
    mean = np.zeros(J)
    if J == 1:  # numpy sums a single column as one 1-d array: pairwise
        mean[0] = pairwise_sum(Y[:, 0], 0, T)
    else:
        for f in range(J):
            mean[f] = Y[0, f]
        for t in range(1, T):
            for f in range(J):
                mean[f] += Y[t, f]
    for f in range(J):
        mean[f] /= T
    row = np.empty(J)
    dist = np.empty(T)
    for t in range(T):
        for f in range(J):
            diff = Y[t, f] - mean[f]
            row[f] = diff * diff
        dist[t] = pairwise_sum(row, 0, J)
    return np.sqrt(pairwise_sum(dist, 0, T) / T)


@njit(cache=True)
def roc_episode_error(centers, n_clusters, states, Y, err, known, need_spread, divide):
    """Eq 10 per row (:func:`roc_error`) and, of one episode, the mean error over the rows whose state
    has a cluster (NaN if none) and the features' :func:`spread` (NaN unless ``need_spread``).

    ``divide``: each row's error is divided by the spread first (infinite when the spread is 0).
    Returns ``(mean, spread)``. Inputs are validated by the caller (:func:`first_bad`).
    """
    T = Y.shape[0]
    roc_error(centers, n_clusters, states, Y, err, known)
    s = spread(Y) if need_spread else np.nan
    if divide:
        for t in range(T):
            err[t] = err[t] / s if s > 0 else np.inf
    n = 0
    for t in range(T):
        if known[t]:
            n += 1
    if n == T:
        return pairwise_sum(err, 0, T) / n, s
    if n == 0:
        return np.nan, s
    kept = np.empty(n)
    k = 0
    for t in range(T):
        if known[t]:
            kept[k] = err[t]
            k += 1
    return pairwise_sum(kept, 0, n) / n, s


@njit(cache=True)
def first_bad(states, Y, n_states):
    """The first row whose state lies outside ``[0, n_states)`` or whose features are not finite; -1 if none."""
    for t in range(Y.shape[0]):
        if states[t] < 0 or states[t] >= n_states:
            return t
        for f in range(Y.shape[1]):
            if not np.isfinite(Y[t, f]):
                return t
    return -1
