"""Model-based LSPI and value iteration against each other and a closed form."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from neurocur.learn.lspi import LSPI, greedy, lspi, value_iteration


def _random_mdp(seed, S, A, sparse=False):
    rng = np.random.default_rng(seed)
    P = rng.dirichlet(np.ones(S), size=(S, A))
    if sparse:  # some deterministic transitions
        P = np.where(rng.random(P.shape) < 0.5, 0.0, P) + 1e-300
        P /= P.sum(axis=2, keepdims=True)
    R = rng.normal(size=(S, A))
    return P, R


def _engage_mdp(n_contexts):
    """Eqs 12-13: action 0 engage (stay), action 1 disengage (uniformly to another context)."""
    engage = np.eye(n_contexts)
    disengage = (1.0 - np.eye(n_contexts)) / (n_contexts - 1)
    return np.stack([engage, disengage], axis=1)


def _assert_same_greedy(Q_ref, policy, gap=1e-6):
    """Policies agree wherever the reference's best action is not (nearly) tied."""
    ordered = np.sort(Q_ref, axis=1)
    clear = ordered[:, -1] - ordered[:, -2] > gap if Q_ref.shape[1] > 1 else np.ones(len(Q_ref), bool)
    np.testing.assert_array_equal(policy[clear], np.argmax(Q_ref, axis=1)[clear])


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("discount", [0.0, 0.5, 0.9, 0.99])
def test_tabular_lspi_equals_value_iteration(seed, discount):
    P, R = _random_mdp(seed, S=6, A=3, sparse=seed % 2 == 1)
    Q_vi = value_iteration(P, R, discount)
    Q, policy = lspi(P, R, discount)
    np.testing.assert_allclose(Q, Q_vi, atol=1e-8, rtol=0)
    assert policy.dtype == np.int64 and policy.shape == (6,)
    _assert_same_greedy(Q_vi, policy)
    # Q is the fixed point of the Bellman optimality operator
    np.testing.assert_allclose(Q, R + discount * P @ Q.max(axis=1), atol=1e-10)


@settings(max_examples=40, deadline=None)
@given(
    S=st.integers(1, 6),
    A=st.integers(1, 4),
    discount=st.floats(0.0, 0.95),
    seed=st.integers(0, 2**32 - 1),
    sparse=st.booleans(),
)
def test_lspi_equals_value_iteration_property(S, A, discount, seed, sparse):
    P, R = _random_mdp(seed, S, A, sparse)
    Q_vi = value_iteration(P, R, discount)
    Q, policy = lspi(P, R, discount)
    np.testing.assert_allclose(Q, Q_vi, atol=1e-8, rtol=0)
    _assert_same_greedy(Q_vi, policy)


@pytest.mark.parametrize("n_contexts", [2, 3, 5])
@pytest.mark.parametrize("discount", [0.0, 0.5, 0.9])
def test_engage_disengage_one_rewarding_context(n_contexts, discount):
    """Engaging context c pays r; nothing else pays. Closed form:

    V(c) = r / (1 - γ); for the other contexts, disengaging reaches c w.p. 1/(N-1) and
    another unrewarded context otherwise, so v = γ V(c) / (N - 1 - γ (N - 2)).
    Q(c) = [V(c), γ v], Q(s ≠ c) = [γ v, v].
    """
    r, c = 2.5, n_contexts - 1
    P = _engage_mdp(n_contexts)
    R = np.zeros((n_contexts, 2))
    R[c, 0] = r
    V_c = r / (1 - discount)
    v = discount * V_c / (n_contexts - 1 - discount * (n_contexts - 2))
    Q_ref = np.tile([discount * v, v], (n_contexts, 1))
    Q_ref[c] = [V_c, discount * v]
    Q, policy = lspi(P, R, discount)
    np.testing.assert_allclose(Q, Q_ref, rtol=1e-12, atol=1e-12)
    expected = np.ones(n_contexts, dtype=np.int64)  # disengage elsewhere ...
    expected[c] = 0  # ... engage where the reward is
    if discount == 0.0:
        expected[:] = 0  # myopic: elsewhere both actions are worth 0, the tie goes to engage
    np.testing.assert_array_equal(policy, expected)


def test_engage_disengage_boredom_penalty():
    """A familiar context costs -100 per engaged episode; the agent leaves it and stays on the paying one."""
    P = _engage_mdp(5)
    R = np.zeros((5, 2))
    R[0, 0] = -100.0
    R[3, 0] = 1.0
    Q, policy = lspi(P, R, 0.9)
    np.testing.assert_allclose(Q, value_iteration(P, R, 0.9), atol=1e-8)
    np.testing.assert_array_equal(policy, [1, 1, 1, 0, 1])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_full_rank_features_recover_optimal_q(seed):
    """An invertible linear mixing of one-hot features spans the same space: Q* exactly."""
    S, A = 4, 3
    P, R = _random_mdp(seed, S, A)
    rng = np.random.default_rng(50 + seed)
    M = rng.normal(size=(S * A, S * A)) + 3 * np.eye(S * A)
    features = M.reshape(S, A, S * A)
    Q, policy = lspi(P, R, 0.8, features=features)
    Q_vi = value_iteration(P, R, 0.8)
    np.testing.assert_allclose(Q, Q_vi, atol=1e-8)
    _assert_same_greedy(Q_vi, policy)
    # a redundant (duplicated) feature makes A singular: the least-squares solve copes
    Q2, policy2 = lspi(P, R, 0.8, features=np.concatenate([features, features[:, :, :1]], axis=2))
    np.testing.assert_allclose(Q2, Q_vi, atol=1e-8)
    np.testing.assert_array_equal(policy2, policy)


def test_state_aggregation_features():
    """Two identical copies of an MDP aggregated into one feature set give the copy's Q*."""
    P1, R1 = _random_mdp(7, 3, 2)
    S = 6
    P = np.zeros((S, 2, S))
    P[:3, :, :3] = P1 * 0.5
    P[:3, :, 3:] = P1 * 0.5
    P[3:] = P[:3]
    R = np.concatenate([R1, R1])
    features = np.zeros((S, 2, 6))
    for s in range(S):
        for a in range(2):
            features[s, a, (s % 3) * 2 + a] = 1.0
    Q, _ = lspi(P, R, 0.9, features=features)
    Q1 = value_iteration(P1, R1, 0.9)
    np.testing.assert_allclose(Q, np.concatenate([Q1, Q1]), atol=1e-8)


def test_greedy_ties_go_to_lowest_index():
    Q = np.array([[1.0, 1.0, 0.0], [0.0, 2.0, 2.0 + 1e-12], [3.0, 1.0, 3.0]])
    np.testing.assert_array_equal(greedy(Q), [0, 2, 0])
    np.testing.assert_array_equal(greedy(Q, tol=1e-10), [0, 1, 0])


def test_value_iteration_known_values():
    # one state, two actions: Q(a) = R(a) + γ max Q = R(a) + γ R_max / (1 - γ)
    P = np.ones((1, 2, 1))
    R = np.array([[1.0, 3.0]])
    Q = value_iteration(P, R, 0.75)
    np.testing.assert_allclose(Q, [[1.0 + 0.75 * 12.0, 12.0]], rtol=1e-12)


def test_non_convergence_warns():
    P, R = _random_mdp(0, 5, 3)
    with pytest.warns(RuntimeWarning, match="value_iteration"):
        value_iteration(P, R, 0.99, max_iter=3)


def _bad_cases():
    P, R = _random_mdp(0, 3, 2)
    neg = P.copy()
    neg[0, 0] = [1.5, -0.5, 0.0]
    unnorm = P.copy()
    unnorm[1, 1, 0] += 0.01
    nan_R = R.copy()
    nan_R[0, 1] = np.nan
    return [
        (dict(P=neg, R=R), "non-negative"),
        (dict(P=unnorm, R=R), "sum to 1"),
        (dict(P=P[:, :, :2], R=R), "shape"),
        (dict(P=P[0], R=R), "shape"),
        (dict(P=P, R=R[:2]), "R must have shape"),
        (dict(P=P, R=R.ravel()), "R must have shape"),
        (dict(P=P, R=nan_R), "NaN"),
        (dict(P=P, R=R, discount=1.0), "discount"),
        (dict(P=P, R=R, discount=-0.1), "discount"),
        (dict(P=P, R=R, discount="high"), "discount"),
        (dict(P=np.full((3, 2, 3), "x"), R=R), "real numbers"),
    ]


@pytest.mark.parametrize("case, match", _bad_cases())
def test_bad_model_inputs(case, match):
    case = dict(case)
    discount = case.pop("discount", 0.9)
    with pytest.raises(ValueError, match=match):
        lspi(case["P"], case["R"], discount)
    with pytest.raises(ValueError, match=match):
        value_iteration(case["P"], case["R"], discount)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(features=np.ones((3, 2))), "features"),
        (dict(features=np.ones((3, 3, 2))), "features"),
        (dict(features=np.ones((3, 2, 0))), "features"),
        (dict(max_iter=0), "max_iter"),
        (dict(tol=-1.0), "tol"),
    ],
)
def test_bad_solver_options(kwargs, match):
    P, R = _random_mdp(0, 3, 2)
    with pytest.raises(ValueError, match=match):
        lspi(P, R, 0.9, **kwargs)


def test_ties_within_tol_do_not_make_policy_iteration_cycle():
    """A reward model the PFC reaches (5 contexts, one tiny eq-14 entry): with ties within
    ``tol`` going to the lowest index, policy iteration switched context 2 to a worse action
    by 2e-11 and the other contexts back, in a 2-cycle, until max_iter. Switching only to an
    action at least as good as the current one converges, to the optimum."""
    P = _engage_mdp(5)
    R = np.zeros((5, 2))
    R[2, 1] = 2.1868802011349353e-08
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Q, policy = lspi(P, R, 0.999)
    np.testing.assert_array_equal(policy, [1, 1, 1, 1, 1])  # disengage towards the one paying context
    np.testing.assert_allclose(Q, R + 0.999 * P @ Q.max(axis=1), atol=1e-12, rtol=0)  # Bellman optimality
    np.testing.assert_allclose(Q, value_iteration(P, R, 0.999), atol=1e-8, rtol=0)


@settings(max_examples=30, deadline=None)
@given(n=st.integers(2, 6), discount=st.sampled_from([0.5, 0.9, 0.99, 0.999]),
       alpha=st.sampled_from([0.05, 0.2, 1.0]), seed=st.integers(0, 2**32 - 1))
def test_warm_started_pfc_planning_converges_to_the_optimum(n, discount, alpha, seed):
    """The PFC's use: eq 14 updates with DA of -100 (boredom), 0 and small progress, each
    followed by LSPI warm-started from the previous policy; never max_iter, always Q*."""
    rng = np.random.default_rng(seed)
    P = _engage_mdp(n)
    planner, R3, policy = LSPI(P, discount), np.zeros((n, 2, n)), None
    for _ in range(60):
        o, a, o2 = rng.integers(n), rng.integers(2), rng.integers(n)
        da = rng.choice([-100.0, 0.0, rng.normal(0, 0.1), rng.normal(0, 1e-6)])
        R3[o, a, o2] += alpha * (da - R3[o, a, o2])
        R = np.einsum("oas,oas->oa", P, R3)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            Q, policy = planner.solve(R, policy)
    np.testing.assert_allclose(Q, value_iteration(P, R, discount), atol=1e-6 * max(1.0, np.abs(Q).max()), rtol=0)
