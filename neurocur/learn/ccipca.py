"""Candid covariance-free incremental PCA with amnesic averaging (Algorithm 2).

CCIPCA (Weng, Zhang & Hwang 2003) estimates the K leading eigenvectors and
eigenvalues of the input covariance one sample at a time, and from them the whitening
matrix S = [v̂_1 … v̂_K] diag(λ_i^(−1/2)) that IncSFA uses (paper section 2.3). The
mean is tracked with the same amnesic rate η(t) = (1 + μ(t))/t.

Rank-deficient input is normal (frames of a 2-d source are rank 2–3 in hundreds of
dimensions). Components whose eigenvalue is below ``eig_cutoff`` × the largest, or
that fall outside the leading ``var_fraction`` of the variance, are *inactive*: the
whitening uses only the ``n_active_`` active ones, so K above the data's rank cannot
make it blow up.

Initialisation: the K directions start as random orthonormal vectors (from
``random_state``) with eigenvalue 0; the first centred samples then set them.
The rate η(t) is capped at 1, so with a constant amnesic l the first ⌊1 + l⌋ samples
only set the mean (their centred value is 0) and the estimates start after them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._estimator import Estimator, NotFittedError
from ._kernels import active_mask, ccipca_fit
from ._validation import (
    check_block,
    check_fraction,
    check_nonconstant,
    check_positive_int,
    check_random_state,
)


@dataclass(frozen=True)
class AmnesicSchedule:
    """The amnesic parameter μ(t) of Algorithm 2 (Weng et al. 2003).

    μ(t) = 0 for t ≤ t1, c (t − t1)/(t2 − t1) for t1 < t ≤ t2, and c + (t − t2)/r
    after; the learning rate is η(t) = (1 + μ(t))/t. Typical: t1=20, t2=200, c=2..4,
    r=2000..5000.
    """

    t1: float = 20.0
    t2: float = 200.0
    c: float = 2.0
    r: float = 2000.0

    def __post_init__(self):
        for name in ("t1", "t2", "c", "r"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise ValueError(f"AmnesicSchedule.{name} must be a number; got {value!r}")
            if not math.isfinite(value):
                raise ValueError(f"AmnesicSchedule.{name} must be finite; got {value!r}")
        if not 0 <= self.t1 < self.t2:
            raise ValueError(f"AmnesicSchedule needs 0 <= t1 < t2; got t1={self.t1}, t2={self.t2}")
        if self.c < 0:
            raise ValueError(f"AmnesicSchedule.c must be >= 0; got {self.c}")
        if self.r <= 0:
            raise ValueError(f"AmnesicSchedule.r must be > 0; got {self.r}")


def amnesic_params(amnesic) -> tuple[float, float, float, float]:
    """(t1, t2, c, r) for the kernels from an ``AmnesicSchedule`` or a constant ``l`` ≥ 0.

    The constant form μ(t) ≡ l (the paper's "1/t learning rate with amnesic parameter
    l = 2") is encoded as t1 = t2 = 0, c = l, r = ∞.
    """
    if isinstance(amnesic, AmnesicSchedule):
        return float(amnesic.t1), float(amnesic.t2), float(amnesic.c), float(amnesic.r)
    if isinstance(amnesic, bool) or not isinstance(amnesic, (int, float, np.integer, np.floating)):
        raise ValueError(f"amnesic must be a number l >= 0 or an AmnesicSchedule; got {amnesic!r}")
    if not (math.isfinite(amnesic) and amnesic >= 0):
        raise ValueError(f"amnesic must be a finite number >= 0; got {amnesic!r}")
    return 0.0, 0.0, float(amnesic), math.inf


def check_cutoffs(var_fraction, eig_cutoff) -> tuple[float, float]:
    """Validated (var_fraction, eig_cutoff) for the kernels; ``var_fraction=None`` → 0 (off)."""
    frac = 0.0 if var_fraction is None else check_fraction(var_fraction, "var_fraction")
    try:
        cut = float(eig_cutoff)
    except (TypeError, ValueError):
        raise ValueError(f"eig_cutoff must be a number in [0, 1); got {eig_cutoff!r}") from None
    if not 0.0 <= cut < 1.0:
        raise ValueError(f"eig_cutoff must be in [0, 1); got {eig_cutoff!r}")
    return frac, cut


def init_directions(rng: np.random.Generator, n_components: int, n_features: int) -> np.ndarray:
    """Random orthonormal rows, shape (n_components, n_features), the CCIPCA start."""
    q, _ = np.linalg.qr(rng.standard_normal((n_features, n_components)))
    return np.ascontiguousarray(q.T)


class CCIPCA(Estimator):
    """Incremental PCA and whitening (Algorithm 2).

    Parameters
    ----------
    n_components : K, the number of leading components estimated.
    amnesic : a constant amnesic parameter l ≥ 0, or an :class:`AmnesicSchedule`.
    var_fraction : if set, only the leading components explaining this fraction of the
        total variance are active (e.g. 0.98, the paper's iCub setting).
    eig_cutoff : components with eigenvalue below ``eig_cutoff`` × the largest are inactive.
    random_state : seed of the initial directions.

    Attributes (after ``partial_fit``): ``mean_`` (D,); ``eigenvalues_`` (K,) and
    ``components_`` (K, D), sorted by descending eigenvalue; ``n_active_``;
    ``total_variance_`` (trace of the covariance estimate); ``n_samples_seen_``.
    """

    def __init__(self, n_components, *, amnesic=2.0, var_fraction=None, eig_cutoff=1e-3, random_state=None):
        self.n_components = n_components
        self.amnesic = amnesic
        self.var_fraction = var_fraction
        self.eig_cutoff = eig_cutoff
        self.random_state = random_state
        self._validate_params()

    def _validate_params(self) -> None:
        k = check_positive_int(self.n_components, "n_components")
        amnesic_params(self.amnesic)
        check_cutoffs(self.var_fraction, self.eig_cutoff)
        if hasattr(self, "_dirs") and k != self._dirs.shape[0]:
            raise ValueError("n_components cannot change after the first partial_fit; make a new CCIPCA")

    def _start(self, n_features: int) -> None:
        k = self.n_components
        if k > n_features:
            raise ValueError(f"n_components={k} exceeds the number of features ({n_features})")
        rng = check_random_state(self.random_state)
        self._dirs = init_directions(rng, k, n_features)
        self._lam = np.zeros(k)
        self._total = 0.0
        self.mean_ = np.zeros(n_features)
        self.n_samples_seen_ = 0
        self._work = np.empty(n_features)

    def partial_fit(self, X):
        """Update the estimates with the rows of ``X`` (samples × features); returns ``self``.

        The first call needs at least two rows that are not all equal.
        """
        fitted = hasattr(self, "_dirs")
        X = check_block(X, n_features=self.mean_.shape[0] if fitted else None, min_rows=1 if fitted else 2)
        if not fitted:
            check_nonconstant(X)
            self._start(X.shape[1])
        t1, t2, c, r = amnesic_params(self.amnesic)
        self.n_samples_seen_, self._total = ccipca_fit(
            X, self.n_samples_seen_, self.mean_, self._dirs, self._lam, self._total, t1, t2, c, r, self._work
        )
        return self

    def _check_fitted(self) -> None:
        if not hasattr(self, "_dirs"):
            raise NotFittedError(f"this {type(self).__name__} is not fitted yet; call partial_fit first")

    def _active(self) -> np.ndarray:
        """Indices of the active components, by descending eigenvalue."""
        self._check_fitted()
        frac, cut = check_cutoffs(self.var_fraction, self.eig_cutoff)
        mask = np.zeros(self._lam.shape[0], dtype=np.bool_)
        active_mask(self._lam, self._total, cut, frac, mask)
        order = np.argsort(-self._lam, kind="stable")
        return order[mask[order]]

    @property
    def eigenvalues_(self) -> np.ndarray:
        self._check_fitted()
        return np.sort(self._lam)[::-1].copy()

    @property
    def components_(self) -> np.ndarray:
        self._check_fitted()
        return self._dirs[np.argsort(-self._lam, kind="stable")].copy()

    @property
    def n_active_(self) -> int:
        return int(self._active().size)

    @property
    def total_variance_(self) -> float:
        self._check_fitted()
        return float(self._total)

    def whitening_matrix(self) -> np.ndarray:
        """S (D, n_active): v̂_i / √λ_i for the active components; z = Sᵀ(x − mean_)."""
        idx = self._active()
        return self._dirs[idx].T / np.sqrt(self._lam[idx])

    def transform(self, X) -> np.ndarray:
        """Whitened signal (X − mean_) S, shape (T, n_active_)."""
        self._check_fitted()
        X = check_block(X, n_features=self.mean_.shape[0])
        return (X - self.mean_) @ self.whitening_matrix()
