"""Robust online clustering, amnesic (paper Algorithm 3), one clusterer per context-state.

The hippocampal estimator of CD-MISFA keeps, for every context-state ``s``, a small set
of at most ξ cluster centres ``c_j`` with weights ``a_j`` over the slow-feature outputs
``y`` seen in that state (paper eq 3, Algorithm 3, after Guedalia et al. 1999). The
state estimation error is eq 10, ``e_s = min_j ||y − c_j||``.

:class:`ROCBank` holds all clusterers of one module in dense arrays and runs
Algorithm 3 literally, sample by sample, in one compiled call per block:

1. while the state has fewer than ξ clusters, ``y`` becomes a new cluster of weight 0;
2. otherwise the winner (largest RESPONSE) moves by ``(y − c)/(a + 1)`` and its weight
   grows by RESPONSE(y, c) evaluated at the moved centre (line 7 follows line 6);
3. the two closest centres (largest mutual RESPONSE) ``g < d`` are merged, weight-averaged,
   into ``g``; ``y`` becomes a new cluster of weight 0 in the freed slot ``d``;
4. all weights leak by the factor ``(1 − φ)`` (``amnesic`` = φ).

So after ξ samples a state always holds its latest sample as a weight-0 cluster (the
"latest-sample cluster", ``ROCBank.latest_``) next to ξ − 1 amnesic weighted means.

RESPONSE. The paper does not define it. We use the Gaussian kernel

    RESPONSE(y, c) = exp(−||y − c||² / (2σ²)),  σ = ``width`` (default 1.0).

Why this kernel:

* it decreases monotonically with distance, so the winner (line 5) is the nearest
  centre and the merged pair (line 8) the two closest centres, as the algorithm's
  comment "merge the two closest" says, and the cluster that learns is the one eq 10
  measures the error against;
* it lies in (0, 1], so each sample adds at most 1 to the winner's weight: a weight is a
  leaky count of evidence (about hits/φ in steady state), the ``1/(a + 1)`` step is then a
  running mean, and a pruning threshold reads as an effective number of hits; a far-off
  sample (outlier) adds almost no weight, the "robust" in robust clustering;
* slow-feature outputs have unit variance (constraint 6), so σ = 1 is a scale-free
  default: a sample one standard deviation from the centre adds e^(−1/2) ≈ 0.61.

Only line 7 depends on the kernel's shape; lines 5 and 8 depend only on its ordering.
Equal distances go to the lowest slot. A merge of two weight-0 clusters (0/0 in line 9,
possible for ξ ≥ 3) takes their plain mean, the limit of equal weights.
"""

from __future__ import annotations

from dataclasses import KW_ONLY, MISSING, dataclass

import numpy as np

from ..config import ParamSpec, check_params, param
from ..config.checks import check_block
from ._roc_kernels import first_bad, roc_episode_error, roc_error, roc_partial_fit

#: ``min_weight`` of :meth:`ROCBank.prune`: weights are never negative
MIN_WEIGHT = ParamSpec(float, low=0.0)


@dataclass(eq=False)
class ROCBank:
    """One ROC-Amnesic clusterer (Algorithm 3) per context-state, in dense arrays.

    Parameters
    ----------
    n_states
        number of context-states ``M`` (eq 11).
    n_features
        dimension of the clustered samples (the number of slow features J).
    max_clusters
        ξ > 1, the maximum number of clusters per state.
    amnesic
        φ in [0, 1], the per-update weight leak.
    width
        σ > 0 of the Gaussian RESPONSE (see the module docstring).

    Attributes
    ----------
    centers_
        (n_states, max_clusters, n_features) float64; slots ``>= n_clusters_[s]``
        are unused.
    weights_
        (n_states, max_clusters) float64.
    n_clusters_
        (n_states,) int64, clusters in use per state.
    latest_
        (n_states,) int64, the slot of each state's latest-sample cluster (-1 before
        the state's first sample).

    Notes
    -----
    The parameters are dataclass fields, stored checked and coerced (ints, floats);
    ``prune``'s ``min_weight`` is checked by :data:`MIN_WEIGHT`.
    """

    n_states: int = param(MISSING, int, low=1)
    n_features: int = param(MISSING, int, low=1)
    _: KW_ONLY
    max_clusters: int = param(2, int, low=2)  # Algorithm 3 merges pairs
    amnesic: float = param(0.01, float, low=0.0, high=1.0)
    width: float = param(1.0, float, low=0.0, low_open=True)

    def __post_init__(self):
        check_params(self)
        self.centers_ = np.zeros((self.n_states, self.max_clusters, self.n_features))
        self.weights_ = np.zeros((self.n_states, self.max_clusters))
        self.n_clusters_ = np.zeros(self.n_states, dtype=np.int64)
        self.latest_ = np.full(self.n_states, -1, dtype=np.int64)

    def _check(self, states, Y) -> tuple[np.ndarray, np.ndarray]:
        Y = check_block(Y, name="Y", n_features=self.n_features)
        s = np.asarray(states)
        if s.ndim != 1 or s.dtype.kind not in "iu":
            raise ValueError(
                f"states must be a 1-d array of integers (one context-state per row of Y); "
                f"got shape {s.shape} and dtype {s.dtype}"
            )
        if len(s) != len(Y):
            raise ValueError(f"states and Y must have equal lengths; got {len(s)} states and {len(Y)} rows of Y")
        lo, hi = s.min(), s.max()
        if lo < 0 or hi >= self.n_states:
            bad = lo if lo < 0 else hi
            raise ValueError(f"states must lie in [0, {self.n_states}); got {bad}")
        return np.ascontiguousarray(s, dtype=np.int64), Y

    def _fast(self, states, Y) -> tuple[np.ndarray, np.ndarray]:
        """``(states, Y)`` as given when they are int64 and float64 arrays of the right shapes whose
        values one compiled pass finds valid; otherwise :meth:`_check`'s conversion, or its error."""
        s, Y_ = np.asarray(states), np.asarray(Y)
        if (s.dtype == np.int64 and Y_.dtype == np.float64 and s.ndim == 1 and Y_.ndim == 2
                and Y_.shape == (len(s), self.n_features) and len(s) and first_bad(s, Y_, self.n_states) < 0):
            return s, Y_
        return self._check(states, Y)

    def partial_fit(self, states, Y) -> ROCBank:
        """Run Algorithm 3 on each row ``Y[t]`` with the clusterer of ``states[t]``, in order."""
        s, Y = self._fast(states, Y)
        roc_partial_fit(
            self.centers_, self.weights_, self.n_clusters_, self.latest_, s, Y,
            self.amnesic, 0.5 / self.width**2,
        )
        return self

    def error(self, states, Y) -> tuple[np.ndarray, np.ndarray]:
        """Eq 10 per row: ``(err (T,), known (T,) bool)``; ``err`` is 0.0 where the state has no cluster."""
        s, Y = self._fast(states, Y)
        err = np.empty(len(Y))
        known = np.empty(len(Y), dtype=np.bool_)
        roc_error(self.centers_, self.n_clusters_, s, Y, err, known)
        return err, known

    def episode_error(self, states, Y, *, spread: bool = False, divide: bool = False):
        """Eq 10 per row of one episode, with the episode's figures, in one compiled call.

        Returns ``(err, known, mean, spread)``: :meth:`error`'s ``err`` and ``known``, the
        mean error over the rows whose state has a cluster (NaN if none) and, if ``spread``,
        the features' spread ``sqrt(mean_t ||Y[t] - mean(Y)||²)`` (else NaN). ``divide``
        (needs ``spread``): every row's error is divided by the spread first (infinite when
        it is 0). Inputs are checked as by :meth:`error`.
        """
        s, Y = self._fast(states, Y)
        err = np.empty(len(Y))
        known = np.empty(len(Y), dtype=np.bool_)
        mean, found = roc_episode_error(self.centers_, self.n_clusters_, s, Y, err, known, spread or divide, divide)
        return err, known, mean, found

    def prune(self, min_weight) -> int:
        """Remove clusters of weight below ``min_weight`` ≥ 0 (section 2.6), keeping each latest-sample cluster.

        The latest-sample cluster has weight 0 by construction; removing it would leave only
        a stale mean. Remaining clusters keep their order and are packed to the front.
        Returns the number of clusters removed.
        """
        m = MIN_WEIGHT.coerce(min_weight, source="ROCBank.prune", key="min_weight")
        slot = np.arange(self.max_clusters)
        used = slot < self.n_clusters_[:, None]
        keep = used & ((self.weights_ >= m) | (slot == self.latest_[:, None]))
        removed = int(used.sum() - keep.sum())
        if removed:
            order = np.argsort(~keep, axis=1, kind="stable")  # kept slots first, in order
            self.centers_ = np.take_along_axis(self.centers_, order[:, :, None], axis=1)
            self.weights_ = np.take_along_axis(self.weights_, order, axis=1)
            n_new = keep.sum(axis=1)
            unused = slot >= n_new[:, None]
            self.centers_[unused] = 0.0
            self.weights_[unused] = 0.0
            has = self.latest_ >= 0
            rank = np.cumsum(keep, axis=1) - 1  # new slot of each kept old slot
            self.latest_[has] = rank[has, self.latest_[has]]
            self.n_clusters_ = n_new.astype(np.int64)
        return removed

    def copy(self) -> ROCBank:
        """An independent deep copy."""
        new = ROCBank(
            self.n_states, self.n_features, max_clusters=self.max_clusters, amnesic=self.amnesic, width=self.width
        )
        new.centers_ = self.centers_.copy()
        new.weights_ = self.weights_.copy()
        new.n_clusters_ = self.n_clusters_.copy()
        new.latest_ = self.latest_.copy()
        return new
