"""Minor components analysis by CIMCA (Peng & Yi 2006; paper eqs 8, 16, 17).

The J vectors w_1..w_J converge to the eigenvectors of the *smallest* eigenvalues of
the second-moment matrix C = E[z zᵀ] of the input rows z (w_1 the smallest), one sample at a time:

    w_i ← (1 − η) w_i − η [(z·w_i) z + γ Σ_{j<i} (w_j·w_i) w_j],   w_i ← w_i / ||w_i||

updated in order i = 1..J with the already updated w_j (sequential lateral term).

γ must exceed the largest eigenvalue λ_1 of C: the lateral term raises the found
directions' eigenvalues by γ so that the next vector converges to the next minor
component (γ > λ_{n−J+1} − λ_n is what is needed; γ > λ_1 is the safe bound).
Convergence also needs 0 < η ≤ 0.5 and η λ_1 < 0.5 (eq 20).

``gamma="auto"`` estimates λ_1 online (a one-component CCIPCA on z with rate 1/t)
and uses γ = ``AUTO_GAMMA_FACTOR`` × λ̂_1.

**Rates per component** (:func:`component_rates`). The paper gives every vector the same
η (``"equal"``). ``"decreasing"`` keeps η for the minor component w_1 and
slows the others, η_i = η / (1.5 (1 + 1.2 (i − 1))) for i ≥ 2: Peng & Yi's (2006)
per-component rate η/(1 + 1.2 (i − 1)), with the base factor 1.5 of mdp-toolkit's CIMCA
(``MCANode``: w ← (1.5 − η) w − η C w), which under the normalisation is the same as
dividing the rate by 1.5; the first vector keeps the paper's rule exactly. The later
vectors chase the earlier ones through the lateral term, and their steady-state
misadjustment grows with η; the slower rates let them settle (on mdp-toolkit's IncSFA test
every feature reaches |corr| ≥ 0.99 with batch SFA instead of 0.98 / 0.95 / 0.83 for
features 2–4; ``tests/learn/test_incsfa.py``).
``"reference"`` (the default) is the rule of the IncSFA author's own code (Kompella,
``varunrajk/IncSFA``, ``mca.py``): w_i ← (1.5 − η_i) w_i − η_i C_i w_i with η_i = η/(1 + 1.2 (i − 1))
for *every* vector, which under the normalisation is the update above at η_i / 1.5, the
slowest vector included. That code also sets γ = 1.2 · 0.2/η (``gamma="reference"``).
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import numpy as np

from ..config import param, spec_param
from ..config.checks import RANDOM_STATE, check_random_state
from ._estimator import Estimator
from ._kernels import cimca_fit

#: Safety factor over the online estimate of λ_1 when ``gamma="auto"``.
AUTO_GAMMA_FACTOR = 2.0


#: γ = REFERENCE_GAMMA / η for ``gamma="reference"``: the IncSFA author's code sets γ = 1.2 · 0.2/η
REFERENCE_GAMMA = 1.2 * 0.2


def gamma_code(gamma, learning_rate: float) -> float:
    """The kernels' encoding of a checked γ: a given γ > 0 as itself, ``"reference"`` as
    ``REFERENCE_GAMMA / learning_rate``, ``"auto"`` as −1."""
    if gamma == "reference":
        return REFERENCE_GAMMA / learning_rate
    return -1.0 if gamma == "auto" else gamma


#: The per-component rate rules of CIMCA (see the module docstring).
RATE_RULES = ("equal", "decreasing", "reference")


def component_rates(learning_rate: float, n_components: int, rule: str) -> np.ndarray:
    """The rate of each CIMCA vector, shape (n_components,): all ``learning_rate`` (``"equal"``,
    the paper's eq 16), or ``learning_rate`` for the first and ``learning_rate / (1.5 (1 + 1.2 i))``
    for the vector of index i ≥ 1 (``"decreasing"``, Peng & Yi 2006 with mdp-toolkit's factor 1.5),
    or ``learning_rate / (1.5 (1 + 1.2 i))`` for every index i ≥ 0 (``"reference"``, the IncSFA
    author's code)."""
    rates = np.full(n_components, float(learning_rate))
    if rule in ("decreasing", "reference"):
        first = 0 if rule == "reference" else 1
        i = np.arange(first, n_components)
        rates[first:] = learning_rate / (1.5 * (1.0 + 1.2 * i))
    elif rule != "equal":
        raise ValueError(f"rule must be one of {', '.join(RATE_RULES)}; got {rule!r}")
    return rates


def init_weights(rng: np.random.Generator, n_components: int, n_features: int) -> np.ndarray:
    """Random unit rows, shape (n_components, n_features), the CIMCA start."""
    w = rng.standard_normal((n_components, n_features))
    return w / np.linalg.norm(w, axis=1, keepdims=True)


@dataclass(eq=False, repr=False)
class MCA(Estimator):
    """Online minor components (CIMCA) of the second moment of the rows of ``X``, a
    scikit-learn transformer.

    Parameters
    ----------
    n_components
        J, the number of minor components.
    learning_rate
        η in (0, 0.5].
    component_rates
        ``"reference"`` (the default: the IncSFA author's code, every vector at
        η/(1.5 (1 + 1.2 i))), ``"decreasing"`` (the first vector at η, the later ones as in
        ``"reference"``) or ``"equal"`` (the paper's eq 16: every vector at η); :func:`component_rates`.
    gamma
        the lateral weight γ > λ_1, ``"reference"`` (γ = 1.2 · 0.2/η, the IncSFA author's
        code's, for whitened input) or ``"auto"`` (the default). A given γ is
        checked against the online estimate λ̂_1 after each ``partial_fit``: if γ ≤ λ̂_1
        the call is undone and raises ``ValueError``.
    random_state
        seed of the initial vectors.

    Notes
    -----
    CIMCA is not scale-free: it converges at a rate set by η times the eigenvalues, and
    needs η λ_1 < 0.5 (eq 20), so the input's scale matters (whitened input, as in IncSFA,
    has λ_1 ≤ 4 for its derivative).

    Attributes (after ``fit`` or ``partial_fit``): ``n_features_in_`` (D);
    ``components_`` (J, D), unit rows, the first the estimate of the minor eigenvector;
    ``gamma_`` (the γ in use); ``n_samples_seen_``.
    """

    n_components: int = param(2, int, low=1)
    _: KW_ONLY
    learning_rate: float = param(0.05, float, low=0.0, high=0.5, low_open=True)  # eq 20
    component_rates: str = param("reference", str, choices=RATE_RULES)
    gamma: float | str = param("auto", float, low=0.0, low_open=True, choices=("auto", "reference"))
    random_state: int | np.random.SeedSequence | np.random.Generator | None = spec_param(None, RANDOM_STATE)
    _centred = False  # CIMCA learns the second moment E[z zᵀ], not the covariance

    def _check_params(self, params: dict) -> None:
        if self.__sklearn_is_fitted__() and params["n_components"] != self._W.shape[0]:
            raise ValueError("n_components cannot change after the first partial_fit; make a new MCA")

    def _start(self, n_features: int) -> None:
        j = self.n_components
        if j > n_features:
            raise ValueError(f"n_components={j} exceeds the number of features of X (n_features = {n_features})")
        rng = check_random_state(self.random_state)
        self._W = init_weights(rng, j, n_features)
        self._gdir = init_weights(rng, 1, n_features)
        self._glam = np.zeros(1)
        self.n_samples_seen_ = 0
        self._work = (np.ones(n_features, dtype=np.bool_), np.empty(j), np.empty(n_features), np.empty(n_features))

    def partial_fit(self, X, y=None):
        """Update the minor components with the rows of ``X``; returns ``self``. ``y`` is ignored."""
        params = self._checked_params()
        first = not self.__sklearn_is_fitted__()
        X = self._check_X(X, learn=True)
        gamma = gamma_code(params["gamma"], params["learning_rate"])
        rates = component_rates(params["learning_rate"], params["n_components"], params["component_rates"])
        if first:
            self._start(X.shape[1])
        saved = (self._W.copy(), self._gdir.copy(), self._glam.copy(), self.n_samples_seen_)
        mask, coup, new, res = self._work
        self.n_samples_seen_ = cimca_fit(
            X, self._W, rates, gamma, AUTO_GAMMA_FACTOR if gamma < 0 else 0.0,
            self._gdir, self._glam, self.n_samples_seen_, mask, coup, new, res,
        )
        if 0 < gamma <= self._glam[0]:
            lam1 = float(self._glam[0])
            if first:
                self._unfit()
            else:
                self._W, self._gdir, self._glam, self.n_samples_seen_ = saved
            raise ValueError(
                f"gamma={gamma} must exceed the largest eigenvalue of X's second moment "
                f"(estimated λ_1 = {lam1:.4g}); use a larger gamma or gamma='auto'"
            )
        return self

    @property
    def components_(self) -> np.ndarray:
        self._check_fitted()
        return self._W.copy()

    @property
    def gamma_(self) -> float:
        """The γ in use: the given one (``"reference"``: 1.2 · 0.2/η), or AUTO_GAMMA_FACTOR × the current λ̂_1."""
        params = self._checked_params()
        gamma = gamma_code(params["gamma"], params["learning_rate"])
        if gamma > 0:
            return gamma
        self._check_fitted()
        return AUTO_GAMMA_FACTOR * float(self._glam[0])

    def transform(self, X) -> np.ndarray:
        """Projections X wᵀ_j on the minor components, shape (T, n_components), the minor
        one first. X is not centred: CIMCA's components are those of the second moment."""
        X = self._check_X(X, learn=False)
        return X @ self._W.T
