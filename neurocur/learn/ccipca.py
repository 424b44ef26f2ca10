"""Candid covariance-free incremental PCA with amnesic averaging (Algorithm 2).

CCIPCA (Weng, Zhang & Hwang 2003) estimates the K leading eigenvectors and
eigenvalues of the input covariance one sample at a time, and from them the whitening
matrix S = [v̂_1 … v̂_K] diag(λ_i^(−1/2)) that IncSFA uses (paper section 2.3). The
mean is a cumulative average (rate 1/t, ``mean_rate="cumulative"``, the default) or is tracked
with the same amnesic rate η(t) = (1 + μ(t))/t (``mean_rate="amnesic"``).

The defaults are those of the IncSFA author's own code (Kompella, ``varunrajk/IncSFA``,
``ccipca.py``, ``signalstats.py``): the amnesic schedule (t1, t2, c, r) = (20, 200, 3, 2000)
(``amnesic="reference"``, :data:`REFERENCE_SCHEDULE`) and the cumulative-average mean. The
paper's synthetic experiment states a constant l = 2 (``amnesic=2.0``).

Rank-deficient input is normal (frames of a 2-d source are rank 2–3 in hundreds of
dimensions). Components whose eigenvalue is below ``eig_cutoff`` × the largest, or
that fall outside the leading ``var_fraction`` of the variance, are *inactive*: the
whitening uses only the ``n_active_`` active ones, so K above the data's rank cannot
make it blow up. The whitened output keeps K columns: an inactive component's is zero.

Initialisation: the K directions start as random orthonormal vectors (from
``random_state``) with eigenvalue 0; the first centred samples then set them.
The rate η(t) is capped at 1, so with a constant amnesic l the first ⌊1 + l⌋ samples
only set the mean and the estimates start after them. Their centred value is 0 only
up to round-off (ū + 1·(x − ū) need not equal x), and whitening by an eigenvalue
learned from round-off alone would amplify it ~1e16-fold, so the first block of a
fresh learner must reach past them (:func:`check_first_block`).
"""

from __future__ import annotations

import math
from dataclasses import KW_ONLY, dataclass

import numpy as np

from ..config import ConfigError, ParamSpec, check_params, describe, param, spec_param
from ..config.checks import RANDOM_STATE, check_random_state
from ._estimator import Estimator
from ._kernels import active_mask, amnesic_rate, ccipca_fit


@dataclass(frozen=True)
class AmnesicSchedule:
    """The amnesic parameter μ(t) of Algorithm 2 (Weng et al. 2003).

    μ(t) = 0 for t ≤ t1, c (t − t1)/(t2 − t1) for t1 < t ≤ t2, and c + (t − t2)/r
    after; the learning rate is η(t) = (1 + μ(t))/t. Typical: t1=20, t2=200, c=2..4,
    r=2000..5000.

    Parameters
    ----------
    t1 : float
        The sample count up to which μ = 0.
    t2 : float
        The sample count at which μ reaches ``c`` (above ``t1``).
    c : float
        μ at ``t2``.
    r : float
        Beyond ``t2``, μ grows by 1 every ``r`` samples.
    """

    t1: float = param(20.0, float, low=0.0)
    t2: float = param(200.0, float, low=0.0)
    c: float = param(2.0, float, low=0.0)
    r: float = param(2000.0, float, low=0.0, low_open=True)

    def __post_init__(self):
        check_params(self)
        if self.t2 <= self.t1:
            raise ConfigError(type(self).__name__, "t2", f"a number > t1 = {self.t1:g}", describe(self.t2))


#: ``amnesic="reference"``: the schedule of the IncSFA author's code, (n1, n2, m, C) = (20, 200, 2000, 3)
REFERENCE_SCHEDULE = AmnesicSchedule(20.0, 200.0, 3.0, 2000.0)
#: the mean's rate: 1/t (a cumulative average) or CCIPCA's amnesic rate
MEAN_RATES = ("cumulative", "amnesic")


def amnesic_params(amnesic) -> tuple[float, float, float, float]:
    """(t1, t2, c, r) for the kernels from a checked ``amnesic``: an ``AmnesicSchedule``, ``"reference"``
    (:data:`REFERENCE_SCHEDULE`) or a constant l.

    The constant form μ(t) ≡ l (the paper's "1/t learning rate with amnesic parameter
    l = 2") is encoded as t1 = t2 = 0, c = l, r = ∞.
    """
    if amnesic == "reference":
        amnesic = REFERENCE_SCHEDULE
    if isinstance(amnesic, AmnesicSchedule):
        return float(amnesic.t1), float(amnesic.t2), float(amnesic.c), float(amnesic.r)
    return 0.0, 0.0, float(amnesic), math.inf


def check_first_block(X: np.ndarray, amnesic) -> None:
    """Raise ``ValueError`` unless some row of a fresh learner's first block ``X`` learns,
    i.e. comes after the samples whose rate η(t) is capped at 1 (they only set the mean)."""
    t1, t2, c, r = amnesic_params(amnesic)
    n = X.shape[0]
    mean_only = 0
    while mean_only < n and amnesic_rate(mean_only + 1, t1, t2, c, r) >= 1.0:
        mean_only += 1
    if mean_only < n:
        return
    limit = n + 10_000  # counted on only for the message
    while mean_only < limit and amnesic_rate(mean_only + 1, t1, t2, c, r) >= 1.0:
        mean_only += 1
    if mean_only < limit:
        count, fix = str(mean_only), f"give a first block of at least {mean_only + 1} rows"
    else:
        count, fix = f"more than {limit}", "use an amnesic schedule whose rate drops below 1"
    raise ValueError(
        f"the first block has {n} rows, all of which only set the mean: with amnesic={amnesic!r} the rate "
        f"η(t) is capped at 1 for the first {count} samples, whose centred value is round-off; {fix}"
    )


def init_directions(rng: np.random.Generator, n_components: int, n_features: int) -> np.ndarray:
    """Random orthonormal rows, shape (n_components, n_features), the CCIPCA start."""
    q, _ = np.linalg.qr(rng.standard_normal((n_features, n_components)))
    return np.ascontiguousarray(q.T)


@dataclass(eq=False, repr=False)
class CCIPCA(Estimator):
    """Incremental PCA and whitening (Algorithm 2), a scikit-learn transformer.

    Parameters
    ----------
    n_components
        K, the number of leading components estimated.
    amnesic
        ``"reference"`` (the default: :data:`REFERENCE_SCHEDULE`, the IncSFA author's code's),
        a constant amnesic parameter l ≥ 0, or an :class:`AmnesicSchedule`.
    mean_rate
        ``"cumulative"`` (the default: the mean is the average of all samples, as in the
        IncSFA author's code) or ``"amnesic"`` (the mean follows CCIPCA's rate η(t)).
    var_fraction
        if set, only the leading components explaining this fraction of the
        total variance are active (e.g. 0.98, the paper's iCub setting).
    eig_cutoff
        components with eigenvalue below ``eig_cutoff`` × the largest are inactive.
    orthonormalize
        every this many samples the directions are made orthonormal again
        by Gram–Schmidt, leading component first (``_kernels.orthonormalize``); 0, the
        default, never does (Algorithm 2 as published). Algorithm 2 keeps them
        orthogonal only approximately; with two nearly equal eigenvalues a later
        component can drift onto an earlier one and the whitening becomes invalid.
    random_state
        seed of the initial directions.

    Notes
    -----
    Attributes (after ``fit`` or ``partial_fit``): ``n_features_in_`` (D); ``mean_`` (D,);
    ``eigenvalues_`` (K,) and ``components_`` (K, D), sorted by descending eigenvalue;
    ``n_active_``; ``total_variance_`` (trace of the covariance estimate);
    ``n_samples_seen_``.
    """

    n_components: int = param(2, int, low=1)
    _: KW_ONLY
    amnesic: float | AmnesicSchedule | str = spec_param(
        "reference", ParamSpec(float, low=0.0, classes=(AmnesicSchedule,), choices=("reference",)))
    mean_rate: str = param("cumulative", str, choices=MEAN_RATES)
    var_fraction: float | None = param(None, float, low=0.0, high=1.0, low_open=True, optional=True)
    eig_cutoff: float = param(1e-3, float, low=0.0, high=1.0, high_open=True)
    orthonormalize: int = param(0, int, low=0)
    random_state: int | np.random.SeedSequence | np.random.Generator | None = spec_param(None, RANDOM_STATE)
    _min_first_rows = 2  # a variance needs two samples

    def _check_params(self, params: dict) -> None:
        if self.__sklearn_is_fitted__() and params["n_components"] != self._dirs.shape[0]:
            raise ValueError("n_components cannot change after the first partial_fit; make a new CCIPCA")

    def _start(self, n_features: int) -> None:
        k = self.n_components
        if k > n_features:
            raise ValueError(f"n_components={k} exceeds the number of features of X (n_features = {n_features})")
        rng = check_random_state(self.random_state)
        self._dirs = init_directions(rng, k, n_features)
        self._lam = np.zeros(k)
        self._total = 0.0
        self.mean_ = np.zeros(n_features)
        self.n_samples_seen_ = 0
        self._work = np.empty(n_features)

    def partial_fit(self, X, y=None):
        """Update the estimates with the rows of ``X`` (samples × features); returns ``self``.

        The first call needs rows that are not all equal, more than the samples that only
        set the mean (the first sample for the default schedule; ⌊1 + l⌋ for a constant
        amnesic l, so at least 4 rows for l = 2; see :func:`check_first_block`). ``y`` is ignored.
        """
        params = self._checked_params()
        first = not self.__sklearn_is_fitted__()
        X = self._check_X(X, learn=True)
        if first:
            check_first_block(X, params["amnesic"])
            self._start(X.shape[1])
        t1, t2, c, r = amnesic_params(params["amnesic"])
        self.n_samples_seen_, self._total = ccipca_fit(
            X, self.n_samples_seen_, self.mean_, self._dirs, self._lam, self._total, t1, t2, c, r,
            params["mean_rate"] == "cumulative", params["orthonormalize"], self._work,
        )
        return self

    def _active(self) -> np.ndarray:
        """Indices of the active components, by descending eigenvalue."""
        self._check_fitted()
        params = self._checked_params()
        frac = 0.0 if params["var_fraction"] is None else params["var_fraction"]  # 0: off
        mask = np.zeros(self._lam.shape[0], dtype=np.bool_)
        active_mask(self._lam, self._total, params["eig_cutoff"], frac, mask)
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
        """S (D, K), z = Sᵀ(x − mean_): column i is v̂_i / √λ_i for the i-th component by
        descending eigenvalue if it is active (the active ones are the leading
        ``n_active_``), zeros if it is not."""
        idx = self._active()
        S = np.zeros((self._dirs.shape[1], self._dirs.shape[0]))
        S[:, : idx.size] = self._dirs[idx].T / np.sqrt(self._lam[idx])
        return S

    def transform(self, X) -> np.ndarray:
        """Whitened signal (X − mean_) S, shape (T, n_components): the leading ``n_active_``
        columns are the active components by descending eigenvalue, the other columns
        (inactive or not yet learned components) are zeros."""
        X = self._check_X(X, learn=False)
        return (X - self.mean_) @ self.whitening_matrix()
