"""CCIPCA (Algorithm 2) against numpy's eigendecomposition."""

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from neurocur.learn._kernels import amnesic_rate
from neurocur.learn.ccipca import CCIPCA, AmnesicSchedule

SPECTRUM = np.array([10.0, 6.0, 3.0, 1.5, 0.5, 0.3, 0.2, 0.1, 0.1, 0.1])


def gaussian(spectrum, n, seed, offset=3.0):
    rng = np.random.default_rng(seed)
    d = len(spectrum)
    q, _ = np.linalg.qr(rng.standard_normal((d, d)))
    return (rng.standard_normal((n, d)) * np.sqrt(spectrum)) @ q.T + offset


@pytest.fixture(scope="module")
def stationary():
    X = gaussian(SPECTRUM, 20_000, seed=3)
    lam, V = np.linalg.eigh(np.cov(X.T))
    return X, lam[::-1], V[:, ::-1]


@pytest.mark.parametrize(
    ("amnesic", "rtol", "max_angle_deg"),
    [(2.0, 0.05, 2.0), (AmnesicSchedule(t1=20, t2=200, c=2.0, r=2000.0), 0.10, 3.0)],
)
def test_matches_eigh(stationary, amnesic, rtol, max_angle_deg):
    X, lam, V = stationary
    pca = CCIPCA(4, amnesic=amnesic, random_state=0).partial_fit(X)
    np.testing.assert_allclose(pca.eigenvalues_, lam[:4], rtol=rtol)
    angles = np.rad2deg(scipy.linalg.subspace_angles(pca.components_.T, V[:, :4]))
    assert angles.max() < max_angle_deg
    for i in range(4):  # each vector individually, not only the subspace
        assert abs(pca.components_[i] @ V[:, i]) > np.cos(np.deg2rad(max_angle_deg))
    np.testing.assert_allclose(pca.mean_, X.mean(axis=0), atol=0.05)
    Z = pca.transform(X)
    assert Z.shape == (len(X), 4)
    np.testing.assert_allclose(np.cov(Z.T), np.eye(4), atol=0.1)


def test_partial_fit_in_blocks_equals_one_call(stationary):
    X = stationary[0][:3000]
    a = CCIPCA(3, random_state=1).partial_fit(X)
    b = CCIPCA(3, random_state=1)
    for start in range(0, 3000, 100):
        b.partial_fit(X[start : start + 100])
    np.testing.assert_array_equal(a.components_, b.components_)
    np.testing.assert_array_equal(a.eigenvalues_, b.eigenvalues_)
    assert b.n_samples_seen_ == 3000


@pytest.mark.parametrize(("fraction", "expected"), [(0.98, 3), (0.8, 2), (0.5, 1)])
def test_variance_fraction_picks_k(fraction, expected):
    # cumulative fractions: 0.553, 0.830, 0.996, ...
    spectrum = np.array([10.0, 5.0, 3.0, 0.01, 0.01, 0.01, 0.01, 0.01])
    X = gaussian(spectrum, 20_000, seed=4)
    pca = CCIPCA(6, var_fraction=fraction, random_state=0).partial_fit(X)
    assert pca.n_active_ == expected
    # fixed width: the inactive components' columns are zeros
    assert pca.whitening_matrix().shape == (8, 6)
    Z = pca.transform(X[:10])
    assert Z.shape == (10, 6)
    assert np.all(Z[:, expected:] == 0) and np.all(Z[:, :expected] != 0)
    assert pca.total_variance_ == pytest.approx(spectrum.sum(), rel=0.05)


def test_k_above_rank_does_not_blow_up():
    rng = np.random.default_rng(5)
    t = np.arange(5000)
    sources = np.stack([np.sin(2 * np.pi * t / 1000), np.sin(2 * np.pi * 24 * t / 1000 + 1.0)], axis=1)
    X = 0.5 + sources @ rng.uniform(0, 1, (2, 400)) / 4  # rank 2 in 400 dimensions
    pca = CCIPCA(10, random_state=0).partial_fit(X)
    assert pca.n_active_ == 2
    lam = pca.eigenvalues_
    assert lam[2] < 1e-3 * lam[0]
    Z = pca.transform(X)
    assert Z.shape == (5000, 10)
    assert np.abs(Z).max() < 5.0
    np.testing.assert_allclose(np.cov(Z[:, :2].T), np.eye(2), atol=0.15)
    assert np.all(Z[:, 2:] == 0)


def test_amnesic_schedule_values():
    # μ = 0 (t ≤ t1), linear ramp to c (t1 < t ≤ t2), then c + (t − t2)/r
    args = (20.0, 200.0, 2.0, 2000.0)
    assert amnesic_rate(10, *args) == pytest.approx(1 / 10)
    assert amnesic_rate(110, *args) == pytest.approx(2 / 110)
    assert amnesic_rate(2200, *args) == pytest.approx(4 / 2200)
    # the constant form l = 2 is (0, 0, 2, inf); the rate is capped at 1
    assert amnesic_rate(30, 0.0, 0.0, 2.0, np.inf) == pytest.approx(3 / 30)
    assert amnesic_rate(2, 0.0, 0.0, 2.0, np.inf) == 1.0


@pytest.mark.parametrize(
    "kwargs", [{"t1": 200, "t2": 20}, {"t1": -1}, {"c": -1.0}, {"r": 0.0}, {"t1": float("nan")}, {"c": "2"}]
)
def test_bad_schedule(kwargs):
    with pytest.raises(ValueError):
        AmnesicSchedule(**kwargs)


@pytest.mark.parametrize(
    "kwargs",
    [{"n_components": 0}, {"n_components": 2.5}, {"amnesic": -1.0}, {"amnesic": "2"},
     {"var_fraction": 1.5}, {"var_fraction": 0.0}, {"eig_cutoff": 1.0}, {"eig_cutoff": -0.1}],
)
def test_bad_parameters(kwargs):
    params = {"n_components": 2} | kwargs
    with pytest.raises(ValueError):
        CCIPCA(**params).fit(np.random.default_rng(0).standard_normal((20, 4)))


def test_bad_fit_input():
    pca = CCIPCA(2)
    with pytest.raises(ValueError, match="zero variance"):
        pca.partial_fit(np.ones((10, 3)))
    with pytest.raises(ValueError, match="exceeds"):
        CCIPCA(4).partial_fit(np.random.default_rng(0).standard_normal((10, 3)))
    with pytest.raises(ValueError, match="not fitted"):
        pca.transform(np.zeros((2, 3)))
    pca.partial_fit(np.random.default_rng(0).standard_normal((10, 3)))
    with pytest.raises(ValueError, match="3 features"):
        pca.partial_fit(np.zeros((5, 4)))
    pca.set_params(n_components=3)
    with pytest.raises(ValueError, match="n_components cannot change"):
        pca.partial_fit(np.zeros((5, 3)))
    assert pca.fit(np.random.default_rng(1).standard_normal((10, 3))).components_.shape == (3, 3)  # fit starts afresh


def test_deterministic_and_params():
    X = gaussian(SPECTRUM, 500, seed=6)
    a = CCIPCA(3, random_state=7).partial_fit(X)
    b = CCIPCA(3, random_state=7).partial_fit(X)
    np.testing.assert_array_equal(a.whitening_matrix(), b.whitening_matrix())
    assert a.get_params() == {
        "n_components": 3, "amnesic": "reference", "mean_rate": "cumulative", "var_fraction": None, "eig_cutoff": 1e-3,
        "orthonormalize": 0, "random_state": 7,
    }
    assert repr(a) == "CCIPCA(n_components=3, random_state=7)"  # scikit-learn's: the changed parameters only
    c = a.copy()
    c.partial_fit(X)
    np.testing.assert_array_equal(a.whitening_matrix(), b.whitening_matrix())


BAD_VALUES = st.sampled_from([np.nan, np.inf, -np.inf])


@settings(max_examples=25, deadline=None)
@given(n=st.integers(2, 30), d=st.integers(1, 6), k=st.integers(1, 6), seed=st.integers(0, 2**16))
def test_shapes_property(n, d, k, seed):
    X = np.random.default_rng(seed).standard_normal((n, d))
    if k > d:
        with pytest.raises(ValueError):
            CCIPCA(k).partial_fit(X)
        return
    if n < 4:  # with the constant amnesic l = 2 the rate is 1 up to t = 3: those samples only set the mean
        with pytest.raises(ValueError, match="first 3 samples.*at least 4 rows"):
            CCIPCA(k, amnesic=2.0).partial_fit(X)
        return
    pca = CCIPCA(k, amnesic=2.0, random_state=seed).partial_fit(X)
    Z = pca.transform(X)
    assert Z.shape == (n, k)  # always n_components columns; inactive ones are zeros
    assert np.all(Z[:, pca.n_active_ :] == 0)
    assert 1 <= pca.n_active_ <= k
    assert np.isfinite(Z).all() and np.abs(Z).max() < 1e3  # no whitening of round-off


@settings(max_examples=25, deadline=None)
@given(n=st.integers(2, 20), d=st.integers(1, 5), bad=BAD_VALUES, data=st.data())
def test_nonfinite_rejected_property(n, d, bad, data):
    X = np.random.default_rng(0).standard_normal((n, d))
    X[data.draw(st.integers(0, n - 1)), data.draw(st.integers(0, d - 1))] = bad
    with pytest.raises(ValueError, match="contains (NaN|infinity)"):
        CCIPCA(1).partial_fit(X)


@pytest.mark.parametrize("X", [np.zeros(5), np.zeros((2, 3, 4)), np.array([["a", "b"], ["c", "d"]]), [[1, 2]]])
def test_malformed_rejected(X):
    with pytest.raises(ValueError):
        CCIPCA(1).partial_fit(X)
