"""LSPI's compiled greedy step and policy improvement equal their numpy transcription to the bit."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.learn.lspi import LSPI, greedy
from neurocur.regions.pfc import transition_model


def _numpy_greedy(Q, tol):
    atol = tol * max(1.0, float(np.abs(Q).max()))
    return np.argmax(Q >= Q.max(axis=1, keepdims=True) - atol, axis=1).astype(np.int64)


def _numpy_solve(lspi: LSPI, R, policy):
    """Policy iteration as a plain numpy loop (the module docstring's rule)."""
    Phi, b, w = lspi.Phi, lspi.Phi.T @ R.ravel(), None
    policy = _numpy_greedy(R, lspi.tol) if policy is None else policy
    states = np.arange(lspi.shape[0])
    for _ in range(lspi.max_iter):
        A = Phi.T @ (Phi - lspi.discount * (lspi.P_flat @ lspi.phi[states, policy]))
        w_new = np.linalg.solve(A, b)
        Q = (Phi @ w_new).reshape(lspi.shape)
        new = _numpy_greedy(Q, lspi.tol)
        new = np.where(Q[states, new] < Q[states, policy], policy, new)
        done = np.array_equal(new, policy) or (w is not None and np.max(np.abs(w_new - w)) < lspi.tol)
        w, policy = w_new, new
        if done:
            return Q, policy
    raise AssertionError("no convergence")


def test_greedy_equals_numpy_with_ties_within_tol():
    rng = np.random.default_rng(0)
    for _ in range(300):
        Q = rng.integers(-3, 4, (6, 3)).astype(float) * 10.0 ** rng.integers(-1, 3)
        Q += rng.choice([0.0, 1e-12, -1e-12, 1e-6], Q.shape)  # exact ties, ties within tol, and none
        for tol in (0.0, 1e-10, 1e-7):
            np.testing.assert_array_equal(greedy(Q, tol), _numpy_greedy(Q, tol))
    assert greedy(np.array([[1.0, 1.0 + 1e-12], [2.0, 1.0]]), 1e-10).tolist() == [0, 0]


@pytest.mark.parametrize("n_contexts", [2, 5, 8])
def test_solve_equals_the_numpy_loop(n_contexts):
    rng = np.random.default_rng(n_contexts)
    lspi = LSPI(transition_model(n_contexts), 0.9)
    policy = None
    for _ in range(200):
        R = rng.standard_normal((n_contexts, 2)) * rng.choice([1e-3, 1.0])
        R[rng.random(R.shape) < 0.3] = 0.0  # ties between actions
        Q, new = lspi.solve(R, policy)
        Q_ref, new_ref = _numpy_solve(lspi, R, policy)
        np.testing.assert_array_equal(Q, Q_ref)
        np.testing.assert_array_equal(new, new_ref)
        policy = new
