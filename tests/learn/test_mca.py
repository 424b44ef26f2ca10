"""CIMCA (eqs 8, 16, 17) recovers the minor components of a known covariance."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from neurocur.learn.mca import AUTO_GAMMA_FACTOR, MCA

SPECTRUM = np.array([3.0, 2.0, 1.5, 1.0, 0.5, 0.2])


@pytest.fixture(scope="module")
def known():
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    Z = (rng.standard_normal((20_000, 6)) * np.sqrt(SPECTRUM)) @ q.T
    lam, V = np.linalg.eigh(Z.T @ Z / len(Z))
    return Z, lam, V


@pytest.mark.parametrize("gamma", [4.0, "auto"])
def test_recovers_minor_components(known, gamma):
    Z, lam, V = known
    mca = MCA(2, learning_rate=0.01, gamma=gamma, random_state=0).partial_fit(Z)
    W = mca.components_
    np.testing.assert_allclose(np.linalg.norm(W, axis=1), 1.0, atol=1e-12)
    assert abs(W[0] @ V[:, 0]) > 0.99  # smallest eigenvalue 0.2
    assert abs(W[1] @ V[:, 1]) > 0.98  # next, 0.5
    # the learned vectors' Rayleigh quotients are the two smallest eigenvalues
    C = Z.T @ Z / len(Z)
    np.testing.assert_allclose([w @ C @ w for w in W], lam[:2], rtol=0.15)


def test_auto_gamma_tracks_largest_eigenvalue(known):
    Z, lam, _ = known
    mca = MCA(2, gamma="auto", random_state=0).partial_fit(Z)
    assert mca.gamma_ == pytest.approx(AUTO_GAMMA_FACTOR * lam[-1], rel=0.05)
    assert mca.gamma_ > lam[-1]


def test_gamma_below_largest_eigenvalue_rejected(known):
    Z = known[0]
    with pytest.raises(ValueError, match="must exceed the largest eigenvalue"):
        MCA(2, gamma=2.0).partial_fit(Z)


def test_deterministic_and_blocks(known):
    Z = known[0][:2000]
    a = MCA(2, random_state=5).partial_fit(Z)
    b = MCA(2, random_state=5)
    for start in range(0, 2000, 100):
        b.partial_fit(Z[start : start + 100])
    np.testing.assert_array_equal(a.components_, b.components_)
    assert b.n_samples_seen_ == 2000


@pytest.mark.parametrize(
    "kwargs",
    [{"n_components": 0}, {"learning_rate": 0.0}, {"learning_rate": 0.6}, {"gamma": 0.0},
     {"gamma": -1.0}, {"gamma": "big"}, {"gamma": float("inf")}, {"learning_rate": "0.1"}],
)
def test_bad_parameters(kwargs):
    with pytest.raises(ValueError):
        MCA(**({"n_components": 1} | kwargs)).fit(np.eye(3) * 0.5)


def test_bad_input():
    with pytest.raises(ValueError, match="exceeds"):
        MCA(3).partial_fit(np.eye(2))
    mca = MCA(1).partial_fit(np.eye(3) * 0.5)
    with pytest.raises(ValueError, match="3 features"):
        mca.partial_fit(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="not fitted"):
        _ = MCA(1).components_


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 30), d=st.integers(1, 5), seed=st.integers(0, 2**16))
def test_unit_vectors_property(n, d, seed):
    Z = np.random.default_rng(seed).uniform(-0.5, 0.5, (n, d))
    W = MCA(1, gamma="auto", random_state=seed).partial_fit(Z).components_
    assert W.shape == (1, d)
    assert np.linalg.norm(W) == pytest.approx(1.0)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 20), d=st.integers(1, 5), bad=st.sampled_from([np.nan, np.inf, -np.inf]), data=st.data())
def test_nonfinite_rejected_property(n, d, bad, data):
    Z = np.zeros((n, d))
    Z[data.draw(st.integers(0, n - 1)), data.draw(st.integers(0, d - 1))] = bad
    with pytest.raises(ValueError, match="contains (NaN|infinity)"):
        MCA(1).partial_fit(Z)


@pytest.mark.parametrize("Z", [np.zeros(5), np.zeros((2, 3, 4)), np.array([["a"]]), np.zeros((0, 3))])
def test_malformed_rejected(Z):
    with pytest.raises(ValueError):
        MCA(1).partial_fit(Z)


def test_component_rates():
    from neurocur.learn.mca import component_rates

    np.testing.assert_array_equal(component_rates(0.05, 3, "equal"), [0.05, 0.05, 0.05])
    np.testing.assert_allclose(component_rates(0.05, 4, "decreasing"),
                               [0.05, 0.05 / (1.5 * 2.2), 0.05 / (1.5 * 3.4), 0.05 / (1.5 * 4.6)], rtol=1e-15)
    with pytest.raises(ValueError, match="equal, decreasing"):
        component_rates(0.05, 2, "fast")
    with pytest.raises(ValueError, match="component_rates"):
        MCA(component_rates="fast").partial_fit(np.eye(3))
