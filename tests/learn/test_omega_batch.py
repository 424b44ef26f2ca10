"""Ω (eqs 15, 40) and the batch SFA reference against closed forms."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from neurocur.learn.omega import derivative_eigenvalues, omega, omega_from_eigenvalues
from neurocur.learn.sfa_batch import batch_sfa, whiten_batch

T = np.arange(1000)


def sinusoid_pair(fast_cycles, seed=0, dims=5):
    """Sinusoids of 1 and ``fast_cycles`` cycles per 1000 steps, randomly mixed into ``dims``."""
    S = np.stack([np.sin(2 * np.pi * T / 1000), np.sin(2 * np.pi * fast_cycles * T / 1000)], axis=1)
    return S @ np.random.default_rng(seed).standard_normal((2, dims))


def analytic_eigenvalues(*cycles):
    """A unit-variance sinusoid of angular frequency ω has derivative variance 2(1 − cos ω)."""
    return 2 * (1 - np.cos(2 * np.pi * np.array(cycles) / 1000))


@pytest.mark.parametrize("fast", [57, 24, 12])
def test_matches_closed_form(fast):
    X = sinusoid_pair(fast)
    np.testing.assert_allclose(derivative_eigenvalues(X), analytic_eigenvalues(1, fast), rtol=2e-3)
    assert omega(X, 0.05) == pytest.approx(omega_from_eigenvalues(analytic_eigenvalues(1, fast), 0.05), abs=2e-5)


@pytest.mark.parametrize(("fast", "paper"), [(57, 0.9933), (24, 0.9988), (12, 0.9997)])
def test_paper_values(fast, paper):
    assert omega(sinusoid_pair(fast), 0.05) == pytest.approx(paper, abs=5e-4)


def test_ranks_eigen_gaps():
    values = [omega(sinusoid_pair(f, seed=f), 0.05) for f in (57, 24, 12, 5)]
    assert values == sorted(values)  # larger gap λ_{n-1} − λ_n → smaller Ω → faster learning
    assert len(set(values)) == 4


def test_equal_eigenvalues_and_white_noise():
    assert omega_from_eigenvalues([0.3, 0.3, 1.0], 0.05) == 1.0
    noise = np.random.default_rng(0).standard_normal((20_000, 2))
    assert omega(noise, 0.05) == pytest.approx(1.0, abs=0.005)
    # eq 40 by hand
    assert omega_from_eigenvalues([0.5, 0.1], 0.1) == pytest.approx(1 - 0.1 * 0.4 / (1 - 0.1 - 0.01))


def test_omega_rejects_bad_rates():
    X = sinusoid_pair(24)
    for eta in (0.0, -0.1, 0.6, "a", np.nan):
        with pytest.raises(ValueError):
            omega(X, eta)
    noise = np.random.default_rng(0).standard_normal((500, 3))
    with pytest.raises(ValueError, match="eq 20"):
        omega(noise, 0.5)  # η λ_1 ≈ 1 ≥ 0.5
    with pytest.raises(ValueError, match="at least two"):
        omega_from_eigenvalues([0.1], 0.05)
    with pytest.raises(ValueError, match="at least two"):
        omega(np.sin(2 * np.pi * T / 1000)[:, None], 0.05)


def test_batch_sfa_recovers_slow_source():
    rng = np.random.default_rng(2)
    slow = np.sin(2 * np.pi * 2 * T / 1000)
    others = np.stack([np.sin(2 * np.pi * 37 * T / 1000 + 1), rng.standard_normal(1000)], axis=1)
    S = np.column_stack([slow, others])
    X = S @ rng.standard_normal((3, 8)) + 5.0
    res = batch_sfa(X, 2)
    y = res.transform(X)
    assert abs(np.corrcoef(y[:, 0], slow)[0, 1]) > 0.9999
    np.testing.assert_allclose(y.mean(axis=0), 0, atol=1e-10)
    np.testing.assert_allclose(np.cov(y.T, bias=True), np.eye(2), atol=1e-10)
    assert res.delta[0] == pytest.approx(analytic_eigenvalues(2)[0], rel=5e-3)
    assert res.delta[0] < res.delta[1]
    np.testing.assert_allclose(np.mean(np.diff(y, axis=0) ** 2, axis=0), res.delta, rtol=1e-9)
    Z, W, mean = whiten_batch(X)
    assert Z.shape == (1000, 3)  # rank 3 in 8 dimensions
    with pytest.raises(ValueError, match="exceeds the input's rank"):
        batch_sfa(X, 4)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(5, 40), d=st.integers(2, 5), seed=st.integers(0, 2**16))
def test_batch_sfa_shapes_property(n, d, seed):
    X = np.random.default_rng(seed).standard_normal((n, d))
    res = batch_sfa(X, 1)
    assert res.W.shape == (d, 1)
    assert res.transform(X).shape == (n, 1)
    assert np.isfinite(res.delta).all()


@settings(max_examples=25, deadline=None)
@given(n=st.integers(3, 20), d=st.integers(2, 5), bad=st.sampled_from([np.nan, np.inf, -np.inf]), data=st.data())
def test_nonfinite_rejected_property(n, d, bad, data):
    X = np.random.default_rng(0).standard_normal((n, d))
    X[data.draw(st.integers(0, n - 1)), data.draw(st.integers(0, d - 1))] = bad
    with pytest.raises(ValueError, match="NaN or inf"):
        batch_sfa(X, 1)
    with pytest.raises(ValueError, match="NaN or inf"):
        omega(X, 0.05)


@pytest.mark.parametrize(
    "X", [np.zeros(5), np.zeros((2, 3, 4)), np.array([["a", "b"]] * 4), np.ones((10, 3)), np.zeros((2, 3))]
)
def test_malformed_rejected(X):
    with pytest.raises(ValueError):
        batch_sfa(X, 1)
    with pytest.raises(ValueError):
        omega(X, 0.05)


def test_omega_starts_never_difference_across_episodes():
    rng = np.random.default_rng(3)
    t = np.arange(500)
    a = np.c_[np.sin(2 * np.pi * t / 500), np.sin(2 * np.pi * 20 * t / 500)] @ rng.standard_normal((2, 6))
    b = a[::-1] + 5.0  # a jump at the join would dominate a derivative taken across it
    X = np.vstack([a, b])
    Z, _, _ = whiten_batch(X)
    dZ = np.vstack([np.diff(Z[:500], axis=0), np.diff(Z[500:], axis=0)])
    by_hand = np.linalg.eigvalsh(dZ.T @ dZ / len(dZ))
    np.testing.assert_allclose(derivative_eigenvalues(X, starts=np.array([0, 500])), by_hand, rtol=1e-12, atol=1e-15)
    assert omega(X, 0.05, starts=np.array([0, 500])) == pytest.approx(omega_from_eigenvalues(by_hand, 0.05), abs=1e-14)
    assert not np.allclose(derivative_eigenvalues(X), by_hand)  # the join does change the answer
    for bad in (np.array([0, 1000]), np.array([500, 200]), np.array([0, 499, 500]), np.array([0.0, 500.0])):
        with pytest.raises(ValueError, match="starts must be"):
            omega(X, 0.05, starts=bad)
