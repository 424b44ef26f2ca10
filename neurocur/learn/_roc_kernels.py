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
