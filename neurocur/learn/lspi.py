"""Model-based least-squares policy iteration (Lagoudakis & Parr 2003) for small discrete MDPs.

CD-MISFA's value estimator (paper section 2.8) plans over contexts with the internal
actions engage/disengage, using the known transition model P (eqs 12–13) and the
learned reward model R (eq 14). With the model, LSTDQ evaluates a policy π exactly in
the span of the features φ(s, a):

    A = Σ_{s,a} φ(s,a) (φ(s,a) − γ Σ_{s'} P(s'|s,a) φ(s', π(s')))ᵀ,   b = Σ_{s,a} φ(s,a) R(s,a),
    w = A⁻¹ b,   Q(s, a) = φ(s,a)ᵀ w,

and policy iteration makes π greedy in Q until it no longer changes. With tabular
(one-hot) features this is exact policy iteration and returns the optimal Q*.

Conventions: ``P[s, a, s']`` (shape (S, A, S)), ``R[s, a]`` the expected reward (S, A).
Greedy actions break ties toward the lowest action index; Q values within ``tol``
(relative to the largest |Q|, at least 1) of the best count as tied, so rounding cannot
make the policy alternate between equally good actions. Policy iteration never switches
to a tied action that is worse than the current one: every switch then improves the
policy (Howard's policy improvement), so the loop cannot cycle.
"""

from __future__ import annotations

import warnings
from dataclasses import KW_ONLY, InitVar, dataclass

import numpy as np
from numba import njit

from ..config import check_params, coerce_params, param, param_specs


def _as_finite(x, name: str, ndim: int, shape_doc: str) -> np.ndarray:
    arr = np.asarray(x)
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"{name} must hold real numbers; got dtype {arr.dtype}")
    if arr.ndim != ndim:
        raise ValueError(f"{name} must have shape {shape_doc}; got shape {arr.shape}")
    arr = np.asarray(arr, dtype=np.float64)
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} contains NaN or inf")
    return arr


def _check_mdp(P, R) -> tuple[np.ndarray, np.ndarray]:
    """Validate the model: P (S, A, S) stochastic over s', R (S, A) finite."""
    P = _as_finite(P, "P", 3, "(S, A, S) with P[s, a, s']")
    S, A, S2 = P.shape
    if S2 != S or S == 0 or A == 0:
        raise ValueError(f"P must have shape (S, A, S) with S, A ≥ 1; got shape {P.shape}")
    if (P < 0).any():
        raise ValueError("P must be non-negative (transition probabilities)")
    row_err = np.abs(P.sum(axis=2) - 1.0)
    if (row_err > 1e-8).any():
        s, a = np.unravel_index(np.argmax(row_err), row_err.shape)
        raise ValueError(f"each P[s, a, :] must sum to 1; P[{s}, {a}, :] sums to {P[s, a].sum()!r}")
    R = _as_finite(R, "R", 2, f"(S, A) = ({S}, {A})")
    if R.shape != (S, A):
        raise ValueError(f"R must have shape (S, A) = ({S}, {A}) to match P; got {R.shape}")
    return P, R


def greedy(Q: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """The greedy action per state (int64, (S,)), ties within ``tol`` toward the lowest index."""
    return _greedy(np.asarray(Q, dtype=np.float64), float(tol))


@njit(cache=True)
def _greedy(Q, tol):  # pragma: no cover - compiled
    """:func:`greedy`: the first action whose Q is within ``tol * max(1, max|Q|)`` of its state's best."""
    S, A = Q.shape
    biggest = 1.0
    for s in range(S):
        for a in range(A):
            biggest = max(biggest, abs(Q[s, a]))
    atol = tol * biggest
    policy = np.empty(S, np.int64)
    for s in range(S):
        best = Q[s, 0]
        for a in range(1, A):
            best = max(best, Q[s, a])
        policy[s] = 0
        for a in range(A):
            if Q[s, a] >= best - atol:
                policy[s] = a
                break
    return policy


@njit(cache=True)
def _improve(Q, policy, tol, w_new, w_old, first):  # pragma: no cover - compiled
    """One policy improvement: ``(new policy, done)``. The greedy policy in ``Q``, except that a state
    keeps its action where the greedy one is worse (a tie within ``tol``); done when the policy is
    unchanged or, after the ``first`` iteration, the weights moved by less than ``tol`` (max-norm)."""
    new = _greedy(Q, tol)
    same = True
    for s in range(len(policy)):
        if Q[s, new[s]] < Q[s, policy[s]]:
            new[s] = policy[s]
        same = same and new[s] == policy[s]
    if same or first:
        return new, same
    moved = 0.0
    for i in range(len(w_new)):
        moved = max(moved, abs(w_new[i] - w_old[i]))
    return new, moved < tol


@dataclass(eq=False)
class LSPI:
    """Model-based LSPI for a fixed transition model: validate and factor once, solve often.

    ``LSPI(P, discount, features=None, tol=1e-10).solve(R, policy=None)`` returns
    ``(Q (S, A), policy (S,) int64)``. ``features`` is None for tabular one-hot
    φ(s, a), or an array (S, A, k). The loop starts from ``policy`` (by default the
    policy greedy in R; any start is valid for policy iteration, so a caller that solves
    a slowly changing R can warm-start from the previous answer) and stops when the
    policy is unchanged or the weights move by less than ``tol`` (max-norm); it warns
    if ``max_iter`` is reached. A singular A (redundant features) is solved in the
    least-squares, minimum-norm sense.

    The parameters ``discount``, ``max_iter`` and ``tol`` (also of :func:`lspi` and
    :func:`value_iteration`) are dataclass fields, stored checked and coerced; ``P``, ``R``
    and ``features`` are data, checked as such.
    """

    P: InitVar[np.ndarray]
    discount: float = param(0.9, float, low=0.0, high=1.0, high_open=True)
    _: KW_ONLY
    features: InitVar[np.ndarray | None] = None
    max_iter: int = param(100, int, low=1)
    tol: float = param(1e-10, float, low=0.0)

    def __post_init__(self, P, features):
        P, _ = _check_mdp(P, np.zeros(np.shape(P)[:2]))
        check_params(self)
        S, A, _ = P.shape
        if features is None:
            phi = np.eye(S * A).reshape(S, A, S * A)
        else:
            phi = _as_finite(features, "features", 3, f"(S, A, k) = ({S}, {A}, k)")
            if phi.shape[:2] != (S, A) or phi.shape[2] == 0:
                raise ValueError(f"features must have shape (S, A, k) = ({S}, {A}, k ≥ 1); got {phi.shape}")
        self.shape, self.phi = (S, A), phi
        self.Phi = phi.reshape(S * A, -1)
        self.P_flat = P.reshape(S * A, S)
        self._states = np.arange(S)

    def solve(self, R, policy=None) -> tuple[np.ndarray, np.ndarray]:
        """``(Q, greedy policy)`` for the expected reward ``R`` (S, A)."""
        R = _as_finite(R, "R", 2, f"(S, A) = {self.shape}")
        if R.shape != self.shape:
            raise ValueError(f"R must have shape (S, A) = {self.shape} to match P; got {R.shape}")
        Phi, gamma = self.Phi, self.discount
        b = Phi.T @ R.ravel()
        policy = greedy(R, self.tol) if policy is None else np.asarray(policy, dtype=np.int64)
        w = b  # unused before the first iteration
        for i in range(self.max_iter):
            next_phi = self.P_flat @ self.phi[self._states, policy]  # E[φ(s', π(s')) | s, a]
            A_mat = Phi.T @ (Phi - gamma * next_phi)
            try:
                w_new = np.linalg.solve(A_mat, b)
            except np.linalg.LinAlgError:
                w_new = np.linalg.lstsq(A_mat, b, rcond=None)[0]
            Q = (Phi @ w_new).reshape(self.shape)
            # never switch to an action worse than the current one (greedy's ties within tol could):
            # each switch then improves the policy, so policy iteration cannot cycle
            policy, done = _improve(Q, policy, self.tol, w_new, w, i == 0)
            w = w_new
            if done:
                return Q, policy
        warnings.warn(f"lspi did not converge in max_iter={self.max_iter} iterations", RuntimeWarning, stacklevel=2)
        return Q, policy


def lspi(P, R, discount=0.9, *, features=None, max_iter=100, tol=1e-10) -> tuple[np.ndarray, np.ndarray]:
    """Model-based LSPI: ``(Q (S, A), policy (S,) int64)``; see :class:`LSPI`."""
    return LSPI(P, discount, features=features, max_iter=max_iter, tol=tol).solve(R)


def value_iteration(P, R, discount, tol=1e-12, max_iter=100000) -> np.ndarray:
    """Optimal Q (S, A) by value iteration, Q ← R + γ P max_a Q, until max|ΔQ| < ``tol``.

    Parameters
    ----------
    P : array of shape (S, A, S)
        The transition probabilities P[s, a, s'], stochastic over s'.
    R : array of shape (S, A)
        The expected rewards.
    discount : float
        γ.
    tol : float
        The iteration stops when max|ΔQ| falls below it.
    max_iter : int
        The most iterations.

    Returns
    -------
    array of shape (S, A)
        The optimal Q.
    """
    P, R = _check_mdp(P, R)
    params = coerce_params(param_specs(LSPI), dict(discount=discount, max_iter=max_iter, tol=tol),
                           source="value_iteration")
    gamma, max_iter, tol = params["discount"], params["max_iter"], params["tol"]
    Q = R.copy()
    for _ in range(max_iter):
        Q_new = R + gamma * (P @ Q.max(axis=1))
        delta = np.max(np.abs(Q_new - Q))
        Q = Q_new
        if delta < tol:
            return Q
    warnings.warn(f"value_iteration did not converge in max_iter={max_iter} iterations", RuntimeWarning, stacklevel=2)
    return Q
