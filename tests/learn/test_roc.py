"""ROCBank: Algorithm 3 (ROC-Amnesic) and the eq 10 estimation error."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from neurocur.learn.roc import ROCBank


def _blobs(n_states, n_visits, seed, spread=0.1):
    """Two well-separated Gaussian blobs per state, states visited round-robin."""
    rng = np.random.default_rng(seed)
    means = rng.uniform(-10, 10, size=(n_states, 2, 2))
    states = np.tile(np.arange(n_states), n_visits)
    which = rng.integers(0, 2, size=len(states))
    Y = means[states, which] + spread * rng.normal(size=(len(states), 2))
    return means, states, Y


def _fitted_bank(seed, n_states=7, n_features=3, max_clusters=4, n_samples=200):
    """A bank fitted on random data; states 0 and 1 are never visited."""
    rng = np.random.default_rng(seed)
    states = rng.integers(2, n_states, size=n_samples)
    Y = rng.normal(size=(n_samples, n_features)) * 2.0
    bank = ROCBank(n_states, n_features, max_clusters=max_clusters, amnesic=0.05, width=1.5)
    return bank.partial_fit(states, Y)


def test_recovers_two_blobs_per_state():
    phi = 0.01
    means, states, Y = _blobs(n_states=5, n_visits=3000, seed=1)
    bank = ROCBank(5, 2, max_clusters=3, amnesic=phi).partial_fit(states, Y)
    assert np.all(bank.n_clusters_ == 3)
    for s in range(5):
        heavy = [j for j in range(3) if j != bank.latest_[s]]
        found = bank.centers_[s, heavy]
        # each true mean has one heavy cluster near it (blob sd 0.1; amnesic mean sd ~0.02)
        dist = np.linalg.norm(found[:, None, :] - means[s][None, :, :], axis=2)
        assert sorted(dist.argmin(axis=1)) == [0, 1]
        assert dist.min(axis=0).max() < 0.06
        # steady-state total weight: sum a = r (1 - phi) / phi with response r ~ 0.99
        assert bank.weights_[s].sum() == pytest.approx(0.99 * (1 - phi) / phi, abs=1.0)
        assert bank.weights_[s, bank.latest_[s]] == 0.0


def test_leak_is_geometric_when_not_hit():
    phi, xi = 0.03, 3
    bank = ROCBank(2, 2, max_clusters=xi, amnesic=phi)
    far = np.array([[50.0, 50.0]])
    near = np.zeros((1, 2))
    rng = np.random.default_rng(0)
    # build up a far cluster with positive weight, then a near one
    for y in [far, far, near, far, near, near]:
        bank.partial_fit([0], y + 0.01 * rng.normal(size=(1, 2)))
    far_slot = int(np.argmin(np.linalg.norm(bank.centers_[0] - far, axis=1)))
    assert far_slot != bank.latest_[0]
    a0 = bank.weights_[0, far_slot]
    c0 = bank.centers_[0, far_slot].copy()
    assert a0 > 0
    other = bank.copy()
    other.partial_fit([1, 1], np.ones((2, 2)))
    expected = a0
    for _ in range(40):  # samples near the origin never hit or merge the far cluster
        bank.partial_fit([0], 0.01 * rng.normal(size=(1, 2)))
        expected *= 1 - phi
        assert bank.weights_[0, far_slot] == expected
    np.testing.assert_array_equal(bank.centers_[0, far_slot], c0)
    assert expected == pytest.approx(a0 * (1 - phi) ** 40, rel=1e-12)
    # a state that is not visited does not leak
    np.testing.assert_array_equal(bank.weights_[1], 0.0)


def test_hand_computed_two_cluster_state():
    """ξ = 2, 2-d samples; every step of Algorithm 3 written out by hand."""
    phi, width = 0.1, 2.0
    y1, y2, y3, y4 = np.array([[0.0, 0.0], [3.0, 4.0], [0.6, 0.8], [3.0, 4.0]])
    bank = ROCBank(3, 2, max_clusters=2, amnesic=phi, width=width)
    bank.partial_fit([2, 2], np.array([y1, y2]))
    # lines 2-3 twice: two clusters at the samples, weight 0, no leak
    np.testing.assert_array_equal(bank.centers_[2], [y1, y2])
    np.testing.assert_array_equal(bank.weights_[2], [0.0, 0.0])
    err, known = bank.error([2, 0], np.array([[1.0, 1.0], [1.0, 1.0]]))
    np.testing.assert_allclose(err, [np.sqrt(2.0), 0.0])
    np.testing.assert_array_equal(known, [True, False])

    # y3: winner y1 (distance 1 vs 4) jumps onto y3 (weight 0), weight 1; merge of
    # (y3, a=1) with (y2, a=0) is y3; slot 1 takes y3 with weight 0; leak.
    bank.partial_fit([2], y3[None])
    np.testing.assert_allclose(bank.centers_[2], [y3, y3])
    np.testing.assert_allclose(bank.weights_[2], [1 - phi, 0.0])
    # y4: equal distances, the lowest slot wins; it moves by (y4 - y3)/(a + 1)
    bank.partial_fit([2], y4[None])
    c = y3 + (y4 - y3) / (1 - phi + 1)
    a = (1 - phi) + np.exp(-np.sum((y4 - c) ** 2) / (2 * width**2))
    np.testing.assert_allclose(bank.centers_[2, 0], c, rtol=1e-15)
    np.testing.assert_array_equal(bank.centers_[2, 1], y4)
    np.testing.assert_allclose(bank.weights_[2], [a * (1 - phi), 0.0], rtol=1e-15)
    assert bank.latest_[2] == 1
    # eq 10 after the visits: distance to the nearer of {merged mean, previous sample}
    queries = np.array([[1.0, 1.0], [2.5, 3.0], [10.0, -3.0]])
    expect = [min(np.linalg.norm(q - c), np.linalg.norm(q - y4)) for q in queries]
    err, known = bank.error([2, 2, 2], queries)
    np.testing.assert_allclose(err, expect, rtol=1e-14)
    assert known.all()


def test_merge_of_two_weightless_clusters_is_their_mean():
    """ξ = 3: the closest pair may both have weight 0 (0/0 in line 9): plain mean."""
    bank = ROCBank(1, 1, max_clusters=3, amnesic=0.5)
    bank.partial_fit([0, 0, 0, 0], [[0.0], [10.0], [10.1], [0.05]])
    # winner slot 0 jumps to 0.05 (weight 1); pair (1, 2) merges to 10.05; slot 2 takes 0.05
    np.testing.assert_allclose(bank.centers_[0, :, 0], [0.05, 10.05, 0.05], rtol=1e-15)
    np.testing.assert_array_equal(bank.weights_[0], [0.5, 0.0, 0.0])
    assert bank.latest_[0] == 2


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_error_matches_brute_force(seed):
    bank = _fitted_bank(seed)
    rng = np.random.default_rng(100 + seed)
    states = rng.integers(0, bank.n_states, size=300)
    Y = rng.normal(size=(300, bank.n_features)) * 3.0
    err, known = bank.error(states, Y)
    for t, s in enumerate(states):
        n = bank.n_clusters_[s]
        if n == 0:
            assert not known[t] and err[t] == 0.0
        else:
            assert known[t]
            ref = np.min(np.linalg.norm(Y[t] - bank.centers_[s, :n], axis=1))
            assert err[t] == pytest.approx(ref, rel=1e-13, abs=1e-13)
    assert not known[np.isin(states, [0, 1])].any()


@pytest.mark.parametrize("seed", [3, 4])
def test_prune_matches_reference_and_keeps_latest(seed):
    bank = _fitted_bank(seed, n_states=12, max_clusters=4, n_samples=400)
    before = bank.copy()
    min_weight = float(np.median(bank.weights_[bank.weights_ > 0]))
    removed = bank.prune(min_weight)
    expected_removed = 0
    for s in range(bank.n_states):
        n, latest = before.n_clusters_[s], before.latest_[s]
        kept = [j for j in range(n) if before.weights_[s, j] >= min_weight or j == latest]
        expected_removed += n - len(kept)
        assert bank.n_clusters_[s] == len(kept)
        np.testing.assert_array_equal(bank.centers_[s, : len(kept)], before.centers_[s, kept])
        np.testing.assert_array_equal(bank.weights_[s, : len(kept)], before.weights_[s, kept])
        np.testing.assert_array_equal(bank.centers_[s, len(kept) :], 0.0)
        if latest >= 0:  # the latest-sample cluster survives (weight 0) and is still tracked
            assert bank.weights_[s, bank.latest_[s]] == 0.0
            np.testing.assert_array_equal(bank.centers_[s, bank.latest_[s]], before.centers_[s, latest])
        else:
            assert bank.latest_[s] == -1 and bank.n_clusters_[s] == 0
    assert removed == expected_removed > 0
    assert bank.prune(0.0) == 0


def test_prune_everything_but_latest_then_learn_on():
    bank = ROCBank(1, 2, max_clusters=2, amnesic=0.1)
    Y = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0]])
    bank.partial_fit(np.zeros(4, dtype=int), Y)
    assert bank.prune(1e9) == 1
    assert bank.n_clusters_[0] == 1 and bank.latest_[0] == 0
    np.testing.assert_array_equal(bank.centers_[0, 0], Y[-1])
    err, _ = bank.error([0], [[2.0, 1.0]])
    assert err[0] == pytest.approx(5.0)
    # fewer than ξ clusters again: the next sample is added (lines 2-3)
    bank.partial_fit([0], [[9.0, 9.0]])
    assert bank.n_clusters_[0] == 2 and bank.latest_[0] == 1
    np.testing.assert_array_equal(bank.weights_[0], [0.0, 0.0])


def test_deterministic_and_copy_is_independent():
    means, states, Y = _blobs(4, 50, seed=5)
    a = ROCBank(4, 2, max_clusters=3).partial_fit(states, Y)
    b = ROCBank(4, 2, max_clusters=3)
    for lo in range(0, len(Y), 17):  # block boundaries do not matter
        b.partial_fit(states[lo : lo + 17], Y[lo : lo + 17])
    for name in ("centers_", "weights_", "n_clusters_", "latest_"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    c = a.copy()
    c.partial_fit(states[:10], Y[:10] + 1.0)
    c.prune(1.0)
    np.testing.assert_array_equal(a.centers_, b.centers_)
    np.testing.assert_array_equal(a.weights_, b.weights_)


@settings(max_examples=40, deadline=None)
@given(
    n_states=st.integers(1, 5),
    n_features=st.integers(1, 4),
    xi=st.integers(2, 4),
    seed=st.integers(0, 2**32 - 1),
    T=st.integers(1, 40),
)
def test_invariants(n_states, n_features, xi, seed, T):
    rng = np.random.default_rng(seed)
    states = rng.integers(0, n_states, size=T)
    Y = rng.normal(size=(T, n_features))
    bank = ROCBank(n_states, n_features, max_clusters=xi, amnesic=0.2)
    for t in range(T):
        bank.partial_fit(states[t : t + 1], Y[t : t + 1])
        err, known = bank.error(states[t : t + 1], Y[t : t + 1])
        assert known[0] and err[0] == 0.0  # the latest sample is a cluster
    assert np.all(bank.n_clusters_ <= xi)
    assert np.all(bank.weights_ >= 0)
    visited = bank.latest_ >= 0
    assert np.all(bank.latest_[visited] < bank.n_clusters_[visited])
    assert np.all(bank.weights_[visited, bank.latest_[visited]] == 0.0)
    err, known = bank.error(states, Y)
    assert err.shape == (T,) and known.dtype == bool and np.all(err >= 0)


@settings(max_examples=30, deadline=None)
@given(
    bad=st.sampled_from(
        ["wrong_features", "nan", "inf", "y_1d", "y_3d", "state_high", "state_negative",
         "state_float", "state_2d", "length", "y_strings", "empty"]
    ),
    T=st.integers(1, 6),
    method=st.sampled_from(["partial_fit", "error"]),
)
def test_bad_block_inputs(bad, T, method):
    bank = ROCBank(4, 2)
    states = np.zeros(T, dtype=np.int64)
    Y = np.zeros((T, 2))
    if bad == "wrong_features":
        Y = np.zeros((T, 3))
    elif bad == "nan":
        Y[-1, 0] = np.nan
    elif bad == "inf":
        Y[0, 1] = np.inf
    elif bad == "y_1d":
        Y = np.zeros(T)
    elif bad == "y_3d":
        Y = np.zeros((T, 2, 1))
    elif bad == "state_high":
        states[-1] = 4
    elif bad == "state_negative":
        states[0] = -1
    elif bad == "state_float":
        states = states.astype(float)
    elif bad == "state_2d":
        states = states[:, None]
    elif bad == "length":
        states = np.zeros(T + 1, dtype=np.int64)
    elif bad == "y_strings":
        Y = np.full((T, 2), "a")
    elif bad == "empty":
        states, Y = np.zeros(0, dtype=np.int64), np.zeros((0, 2))
    with pytest.raises(ValueError):
        getattr(bank, method)(states, Y)
    np.testing.assert_array_equal(bank.n_clusters_, 0)


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(n_states=0, n_features=2),
        dict(n_states=3, n_features=2.0),
        dict(n_states=3, n_features=2, max_clusters=1),
        dict(n_states=3, n_features=2, amnesic=1.5),
        dict(n_states=3, n_features=2, amnesic=-0.1),
        dict(n_states=3, n_features=2, width=0.0),
        dict(n_states=3, n_features=2, width=np.nan),
        dict(n_states=3, n_features=2, width="wide"),
    ],
)
def test_bad_parameters(kwargs):
    with pytest.raises(ValueError):
        ROCBank(**kwargs)


def test_bad_prune_threshold():
    with pytest.raises(ValueError, match="min_weight"):
        ROCBank(2, 2).prune(np.nan)
