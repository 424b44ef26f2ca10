"""Incremental slow feature analysis (Kompella, Luciw & Schmidhuber 2012; Algorithm 1).

IncSFA solves linear SFA (paper eqs 4–7) online with two incremental PCAs: CCIPCA
(Algorithm 2) whitens the input, and CIMCA (eqs 8, 16, 17) finds the minor components
of the whitened derivative ż, which are the slow features. The output is
y = Wᵀ Sᵀ (x − ū) (eq 2 with the combined matrix ``projection_`` = S W).

Choices the paper leaves open (see also ``ccipca`` and ``mca``). The defaults are those of
the IncSFA author's own code (Kompella, ``varunrajk/IncSFA``): CCIPCA's amnesic schedule
(20, 200, 3, 2000) and a cumulative-average mean (``ccipca``), CIMCA's per-component rates
η/(1.5 (1 + 1.2 j)) and γ = 1.2 · 0.2/η (``mca``), and the derivative between successively
whitened samples. With them ``IncSFA()`` passes that code's own test
(``tests/learn/test_incsfa_reference.py``). The EC region pins the reproduction's own
choices (``neurocur.regions.ec``).

* Derivative: ``derivative="successive"`` (the default) differences the whitened samples,
  ż(t) = z(t) − z(t−1), each whitened by the matrix and mean of its own time, as the
  author's code does. ``"current"`` takes ż(t) = Sᵀ(x(t) − x(t−1)) with the whitening
  matrix S *current at t*, i.e. both samples whitened by the same matrix: the change of S
  (and of the mean) while the whitening still moves then does not enter ż. One
  ``partial_fit`` call is one episode: the derivative never spans two calls unless
  ``continues=True``.
* Inactive whitened components (eigenvalue below ``eig_cutoff`` × the largest, or
  outside ``var_fraction``) have ż = 0, and the CIMCA vectors are restricted to the
  active coordinates (zeroed elsewhere, renormalised); otherwise CIMCA converges onto
  the zero-variance directions.
* MCA runs from the first derivative, with no warm-up: CIMCA forgets its start at rate
  η, and the whitening of a stationary source settles within a few hundred samples.
* γ: for exact whitening every eigenvalue of E[ż żᵀ] is at most 4, so γ = 4 is always
  safe; the default, the author's γ = 1.2 · 0.2/η, is above 4 for η < 0.06 (4.8 at the
  default η = 0.05). ``gamma="auto"`` uses ``AUTO_GAMMA_FACTOR`` × an online estimate of
  the largest eigenvalue of E[ż żᵀ] (one-component CCIPCA on ż, same amnesic rate).

The whole per-episode loop (mean, CCIPCA, whitening, derivative, CIMCA) is one
compiled call (``_kernels.incsfa_fit``). ``dtype="float32"`` opts into a faster one
(``_kernels_fast.incsfa_fit_fast``): the CCIPCA directions and the per-sample work vectors
are stored in float32, the D-length passes compute and accumulate in float32, and the loops
are compiled with fast-math, so they vectorise. The mean, the eigenvalues and CIMCA stay in float64. Its
results are not bit-identical to the default's (tests/learn/test_incsfa_float32.py
states the agreement).
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, replace

import numpy as np

from ..config import learner_param, param, param_specs, spec_param
from ..config.checks import check_random_state
from ._estimator import Estimator
from ._kernels import incsfa_fit
from ._kernels_fast import incsfa_fit_fast
from .ccipca import CCIPCA, AmnesicSchedule, amnesic_params, check_first_block, init_directions
from .mca import AUTO_GAMMA_FACTOR, MCA, component_rates, gamma_code, init_weights

#: IncSFA's ``dtype`` choices: the exact default and the fast opt-in
DTYPES = ("float64", "float32")
#: K for ``n_pca=None``: min(DEFAULT_PCA, the input's features)
DEFAULT_PCA = 3
#: IncSFA's ``derivative`` choices (see the module docstring)
DERIVATIVES = ("successive", "current")


@dataclass(eq=False, repr=False)
class IncSFA(Estimator):
    """Online linear slow feature analysis, a scikit-learn transformer.

    Parameters
    ----------
    n_components
        J, the number of slow features (J ≤ K).
    n_pca
        K, the number of CCIPCA components used for whitening (K ≤ input dims); ``None``
        (the default) whitens min(3, input dims), so that 2-feature data fit too.
    amnesic
        CCIPCA's amnesic parameter: ``"reference"`` (the default, the author's schedule),
        a constant l or an ``AmnesicSchedule``.
    mean_rate
        ``"cumulative"`` (the default, the average of all samples) or ``"amnesic"``
        (the mean follows CCIPCA's rate); see ``CCIPCA``.
    derivative
        ``"successive"`` (the default: z(t) − z(t−1), each sample whitened at its own
        time) or ``"current"`` (Sᵀ(x(t) − x(t−1)) with the current S).
    var_fraction, eig_cutoff
        which whitened components are active (see ``CCIPCA``).
    orthonormalize
        re-orthonormalise the CCIPCA directions every this many samples
        (see ``CCIPCA``); 0, the default, never does (Algorithm 2 as published).
    mca_rate
        CIMCA's learning rate η in (0, 0.5].
    mca_rates
        ``"reference"`` (the default, the author's code: vector j at η/(1.5 (1 + 1.2 j))),
        ``"decreasing"`` (the slowest feature's vector at η, the others as in ``"reference"``)
        or ``"equal"`` (the paper's eq 16: every vector at η; the EC region's default, so the
        reproduction runs the paper's rule); :func:`~neurocur.learn.mca.component_rates`.
    gamma
        CIMCA's lateral weight: ``"reference"`` (the default, the author's γ = 1.2 · 0.2/η,
        4.8 at η = 0.05), a number > 0 (4 is safe for whitened input) or "auto".
    random_state
        seed of the initial CCIPCA directions and CIMCA vectors.
    dtype
        ``"float64"`` (the default: exact, reproducible to the bit) or ``"float32"``
        (CCIPCA's directions in float32 and fast-math loops: about three times as fast
        on 7500-pixel frames, results equal to float64 only to within round-off that
        grows over a run).

    Notes
    -----
    ``fit(X)`` learns ``X`` as one episode on a fresh state; ``partial_fit`` continues
    the learned state with another episode; ``score`` is the negative slowness.

    Attributes (after ``fit`` or ``partial_fit``): ``n_features_in_`` (D); ``n_pca_`` (the K in
    use: ``n_pca``, or min(3, D) for ``None``); ``mean_`` (D,);
    ``projection_`` (D, J) with ``transform(X) == (X − mean_) @ projection_``;
    ``n_samples_seen_``; ``n_active_`` (whitened components in use); ``eigenvalues_`` (K,)
    CCIPCA's estimates, descending; ``gamma_`` (the γ in use).
    """

    # the whitening's parameters are CCIPCA's, the slow-feature extraction's are MCA's
    n_components: int = learner_param(MCA, "n_components", 2)
    n_pca: int | None = spec_param(None, replace(param_specs(CCIPCA)["n_components"], optional=True))
    _: KW_ONLY
    amnesic: float | AmnesicSchedule | str = learner_param(CCIPCA, "amnesic", "reference")
    mean_rate: str = learner_param(CCIPCA, "mean_rate", "cumulative")
    derivative: str = param("successive", str, choices=DERIVATIVES)
    var_fraction: float | None = learner_param(CCIPCA, "var_fraction", None)
    eig_cutoff: float = learner_param(CCIPCA, "eig_cutoff", 1e-3)
    orthonormalize: int = learner_param(CCIPCA, "orthonormalize", 0)
    mca_rate: float = learner_param(MCA, "learning_rate", 0.05)
    mca_rates: str = learner_param(MCA, "component_rates", "reference")
    gamma: float | str = learner_param(MCA, "gamma", "reference")
    random_state: int | np.random.SeedSequence | np.random.Generator | None = learner_param(CCIPCA, "random_state", None)
    dtype: str = param("float64", str, choices=DTYPES)
    _min_first_rows = 2  # a derivative needs two samples

    def _check_params(self, params: dict) -> None:
        j, k = params["n_components"], params["n_pca"]
        if k is not None and j > k:
            raise ValueError(f"n_components={j} must not exceed n_pca={k}")
        if self.__sklearn_is_fitted__() and (j, self.n_pca_ if k is None else k) != self._W.shape:
            raise ValueError("n_components and n_pca cannot change after the first partial_fit; make a new IncSFA")
        if self.__sklearn_is_fitted__() and np.dtype(params["dtype"]) != self._dirs.dtype:
            raise ValueError("dtype cannot change after the first partial_fit; make a new IncSFA")

    def _start(self, n_features: int) -> None:
        j, k = self.n_components, self.n_pca
        if k is None:
            k = min(DEFAULT_PCA, n_features)
            if j > k:
                raise ValueError(f"n_components={j} exceeds n_pca=None's min({DEFAULT_PCA}, n_features = {n_features}) = {k}")
        elif k > n_features:
            raise ValueError(f"n_pca={k} exceeds the number of features of X (n_features = {n_features})")
        rng = check_random_state(self.random_state)
        store = np.dtype(self.dtype)
        self._dirs = init_directions(rng, k, n_features).astype(store)
        self._W = init_weights(rng, j, k)
        self._gdir = init_weights(rng, 1, k)
        self._lam = np.zeros(k)
        self._glam = np.zeros(1)
        self._total = 0.0
        self._mask = np.zeros(k, dtype=np.bool_)
        self._prev = np.zeros(n_features)
        self._zprev = np.zeros(k)
        self._has_prev = False
        self.mean_ = np.zeros(n_features)
        self.n_pca_ = k
        self.n_samples_seen_ = 0
        self.n_active_ = 0
        # u, dx (D,); ż, ż copy for the γ tracker (K,); lateral couplings (J,); new w (K,)
        self._work = (
            np.empty(n_features, store), np.empty(n_features, store),
            np.empty(k), np.empty(k), np.empty(j), np.empty(k),
        )

    def partial_fit(self, X, y=None, *, continues: bool = False, check_input: bool = True):
        """Learn from one episode ``X`` (rows are consecutive time steps); returns ``self``.

        The derivative is taken only between rows of ``X``; with ``continues=True`` the
        first row is also differenced against the last row of the previous call. The
        first call needs rows that are not all equal, more than the samples that only set
        the mean (2 rows for the default schedule, at least 4 for a constant amnesic l = 2; see
        :func:`~neurocur.learn.ccipca.check_first_block`). ``y`` is ignored.

        ``check_input=False`` skips the checks of ``X`` on a fitted learner (as scikit-learn's
        trees allow): for a caller whose input is already known to be a C-contiguous float64
        array of ``n_features_in_`` finite columns within the learners' range, such as EC's
        frames, which the world's frame contract keeps in [0, 1]. The first block is always checked.
        """
        params = self._checked_params()
        first = not self.__sklearn_is_fitted__()
        if check_input or first:
            X = self._check_X(X, learn=True)
        if first:
            check_first_block(X, params["amnesic"])
            self._start(X.shape[1])
        t1, t2, c, r = amnesic_params(params["amnesic"])
        frac = 0.0 if params["var_fraction"] is None else params["var_fraction"]  # 0: off
        gamma = gamma_code(params["gamma"], params["mca_rate"])
        u, dx, zdot, gres, coup, new = self._work
        kernel = incsfa_fit if params["dtype"] == "float64" else incsfa_fit_fast
        self.n_samples_seen_, self._total, self.n_active_, has_prev = kernel(
            X, self.n_samples_seen_, self._total, bool(continues and self._has_prev),
            self.mean_, self._dirs, self._lam, self._prev, self._zprev, self._W, self._gdir, self._glam,
            t1, t2, c, r, params["mean_rate"] == "cumulative", params["derivative"] == "successive",
            params["orthonormalize"], params["eig_cutoff"], frac,
            component_rates(params["mca_rate"], params["n_components"], params["mca_rates"]), gamma,
            AUTO_GAMMA_FACTOR if gamma < 0 else 0.0,
            self._mask, u, dx, zdot, gres, coup, new,
        )
        self._has_prev = has_prev
        return self

    @property
    def projection_(self) -> np.ndarray:
        """S W, shape (D, J): whitening by the active CCIPCA components, then CIMCA."""
        self._check_fitted()
        m = self._mask
        return (self._dirs[m].T / np.sqrt(self._lam[m])) @ self._W[:, m].T

    @property
    def eigenvalues_(self) -> np.ndarray:
        self._check_fitted()
        return np.sort(self._lam)[::-1].copy()

    @property
    def gamma_(self) -> float:
        """The γ in use: the given one (``"reference"``: 1.2 · 0.2/η), or AUTO_GAMMA_FACTOR × the current λ̂_1(ż)."""
        params = self._checked_params()
        gamma = gamma_code(params["gamma"], params["mca_rate"])
        if gamma > 0:
            return gamma
        self._check_fitted()
        return AUTO_GAMMA_FACTOR * float(self._glam[0])

    def transform(self, X) -> np.ndarray:
        """Slow features (X − mean_) @ projection_, shape (T, n_components), slowest first.

        Always n_components columns; while no whitened component is active (``n_active_``
        is 0: no sample has yet carried variance) every column is zero.
        """
        X = self._check_X(X, learn=False)
        return (X - self.mean_) @ self.projection_

    def delta(self, X) -> np.ndarray:
        """Slowness Δ_j = ⟨ẏ_j²⟩ (eq 4) of each output on ``X``, outputs scaled to unit variance."""
        X = self._check_X(X, learn=False, min_rows=2)
        y = (X - self.mean_) @ self.projection_
        sd = y.std(axis=0)
        if not np.all(sd > 0):
            raise ValueError("delta needs X on which every output varies; some output is constant on X")
        return np.mean(np.diff(y / sd, axis=0) ** 2, axis=0)

    def score(self, X, y=None) -> float:
        """Negative slowness −mean_j Δ_j of the outputs on ``X`` (see :meth:`delta`): higher
        is slower, so model selection (``GridSearchCV``) prefers the slowest features.

        ``X`` is one episode of consecutive time steps; ``y`` is ignored. Each output is
        scaled to unit variance on ``X`` first (SFA's constraint, eq 5), so the score does
        not depend on the outputs' scale. Decorrelation (eq 6) is not scored: outputs that
        repeat one slow direction are not penalised, so compare models by this score with
        ``n_components=1`` or with outputs known to be decorrelated.
        """
        return -float(np.mean(self.delta(X)))
