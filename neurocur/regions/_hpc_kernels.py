"""Compiled per-episode bookkeeping of :class:`neurocur.regions.hpc.HPCROC` (eqs 10-11).

Sums are taken in numpy's pairwise order (:func:`neurocur.learn._roc_kernels.pairwise_sum`),
so every figure is bit-identical to the numpy expressions the docstrings give.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..learn._roc_kernels import pairwise_sum


@njit(cache=True)
def store_errors(history, gated, states, err, known):  # pragma: no cover - compiled
    """Store an episode's eq-10 errors in one context's table and read its figures.

    ``history`` (n + 1, states): each state's stored error at its last visit (row 0; NaN:
    none yet), at the visit before (row 1), ...; ``gated``: each state's last visit was
    familiar. For every frame t whose state has a cluster (``known[t]``): the state's
    errors move one row down (all first, as numpy's ``history[1:, v] = history[:-1, v]``),
    then ``history[0, s] = err[t]`` in frame order. Returns ``(context error, total,
    complete, drift, progress)``: the mean of the stored errors (``row[~nan].sum() / count``,
    NaN if none), eq 11's sum (NaN unless every state has one), whether every state has an
    error or was gated, the ``converged`` rule's extrapolated drift ``mean / (1 - rho)``
    over the states with an error, rho the largest ratio of successive rows' sums (inf if
    one of those states lacks an older error or a ratio is not below 1), and the same-state
    progress: the mean of ``history[0, s_t] - err[t]`` (the row as it was before this
    episode) over the known frames whose state had an error (``drop.mean()``; NaN if none).
    """
    T, n, m = states.shape[0], history.shape[0] - 1, history.shape[1]
    drops, n_drops = np.empty(T), 0
    for t in range(T):
        if known[t] and not np.isnan(history[0, states[t]]):
            drops[n_drops] = history[0, states[t]] - err[t]
            n_drops += 1
    progress = pairwise_sum(drops, 0, n_drops) / n_drops if n_drops else np.nan
    for t in range(T):
        if known[t]:
            for j in range(n, 0, -1):
                history[j, states[t]] = history[j - 1, states[t]]
    for t in range(T):
        if known[t]:
            history[0, states[t]] = err[t]
    kept = np.empty((n + 1, m))
    k, complete, older_nan = 0, True, False
    for i in range(m):
        if np.isnan(history[0, i]):
            complete = complete and gated[i]
        else:
            for j in range(n + 1):
                kept[j, k] = history[j, i]
                older_nan = older_nan or np.isnan(history[j, i])
            k += 1
    now = pairwise_sum(kept[0], 0, k)
    if k == 0:
        mean = total = np.nan
    elif k < m:
        mean, total = now / k, np.nan
    else:
        mean, total = now / m, now
    drift = np.inf
    if not older_nan:
        rho, newer = 0.0, now
        for j in range(1, n + 1):
            older = pairwise_sum(kept[j], 0, k)
            if newer >= older:
                return mean, total, complete, np.inf, progress
            rho = max(rho, newer / older)
            newer = older
        drift = now / k / (1.0 - rho)
    return mean, total, complete, drift, progress
