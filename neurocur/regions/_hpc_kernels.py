"""Compiled per-episode bookkeeping of :class:`neurocur.regions.hpc.HPCROC` (eqs 10-11).

Sums are taken in numpy's pairwise order (:func:`neurocur.learn._roc_kernels.pairwise_sum`),
so every figure is bit-identical to the numpy expressions the docstrings give.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..learn._roc_kernels import pairwise_sum


@njit(cache=True)
def store_errors(row, prev, gated, states, err, known):  # pragma: no cover - compiled
    """Store an episode's eq-10 errors in one context's table and read its figures.

    ``row``: the context's stored error per state (NaN: none yet), ``prev``: each state's
    error at its previous visit, ``gated``: each state's last visit was familiar. For every
    frame t whose state has a cluster (``known[t]``): ``prev[s] = row[s]`` (all first, as
    numpy's ``prev[v] = row[v]``), then ``row[s] = err[t]`` in frame order. Returns
    ``(context error, total, complete, drift)``: the mean of the stored errors
    (``row[~nan].sum() / count``, NaN if none), eq 11's sum (NaN unless every state has
    one), whether every state has an error or was gated, and the ``converged`` rule's
    extrapolated drift ``mean / (1 - rho)``, rho = sum(row) / sum(prev) over the states
    with an error (inf if one lacks a previous error or the errors do not shrink).
    """
    T, m = states.shape[0], row.shape[0]
    for t in range(T):
        if known[t]:
            prev[states[t]] = row[states[t]]
    for t in range(T):
        if known[t]:
            row[states[t]] = err[t]
    kept_row, kept_prev = np.empty(m), np.empty(m)
    k, complete, prev_nan = 0, True, False
    for i in range(m):
        if np.isnan(row[i]):
            complete = complete and gated[i]
        else:
            kept_row[k], kept_prev[k] = row[i], prev[i]
            prev_nan = prev_nan or np.isnan(prev[i])
            k += 1
    now = pairwise_sum(kept_row, 0, k)
    if k == 0:
        mean = total = np.nan
    elif k < m:
        mean, total = now / k, np.nan
    else:
        mean, total = now / m, now
    drift = np.inf
    if not prev_nan:
        before = pairwise_sum(kept_prev, 0, k)
        if now < before:
            drift = now / k / (1.0 - now / before)
    return mean, total, complete, drift
