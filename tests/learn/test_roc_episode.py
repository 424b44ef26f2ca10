"""ROCBank.episode_error: HPC's per-episode figures in one compiled call, bit-identical to numpy."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.learn._roc_kernels import pairwise_sum, spread
from neurocur.learn.roc import ROCBank


def _numpy_spread(y):
    return float(np.sqrt(((y - y.mean(axis=0)) ** 2).sum(axis=1).mean()))


def test_pairwise_sum_is_numpys_sum_to_the_bit():
    rng = np.random.default_rng(0)
    for n in [*range(0, 140), 255, 256, 257, 1000, 1001, 4097, 100_003]:
        a = rng.standard_normal(n) * 10.0 ** rng.uniform(-4, 4, n)  # magnitudes that make the order matter
        assert pairwise_sum(a, 0, n) == a.sum()
    a = rng.standard_normal(600) * 10.0 ** rng.uniform(-4, 4, 600)
    assert pairwise_sum(a, 37, 401) == a[37:438].sum()


def test_spread_is_numpys_to_the_bit_for_arrays_and_strided_views():
    rng = np.random.default_rng(1)
    for T in range(1, 260, 3):
        for J in (1, 2, 3, 9):
            y = rng.standard_normal((T, J)) * 10.0 ** rng.uniform(-2, 2, (T, J))
            assert spread(y) == _numpy_spread(y)
            stacked = rng.standard_normal((T, 3, J))  # a library's features: one module is a strided view
            assert spread(stacked[:, 1, :]) == _numpy_spread(stacked[:, 1, :])
    assert spread(np.ones((5, 2))) == 0.0


def _bank(rng, n_states=30):
    bank = ROCBank(n_states, 2, max_clusters=3)
    for _ in range(4):
        bank.partial_fit(rng.integers(0, n_states - 10, 40), rng.standard_normal((40, 2)))
    return bank  # states n_states - 10 .. n_states - 1 have no cluster


@pytest.mark.parametrize("divide", [False, True])
def test_episode_error_equals_error_and_numpy_means(divide):
    rng = np.random.default_rng(2)
    bank = _bank(rng)
    for states in (rng.integers(0, 20, 150), rng.integers(0, 30, 150), np.arange(20, 30)):
        Y = rng.standard_normal((len(states), 2)) * 3.0
        err, known, mean, s = bank.episode_error(states, Y, spread=True, divide=divide)
        ref_err, ref_known = bank.error(states, Y)
        ref_s = _numpy_spread(Y)
        if divide:
            ref_err = ref_err / ref_s
        np.testing.assert_array_equal(known, ref_known)
        np.testing.assert_array_equal(err, ref_err)
        assert s == ref_s
        if ref_known.any():
            assert mean == float(ref_err[ref_known].sum()) / ref_known.sum()
        else:
            assert np.isnan(mean)
    err, _, _, s = bank.episode_error(np.zeros(3, np.int64), np.ones((3, 2)), spread=True, divide=True)
    assert s == 0.0 and np.isinf(err).all()
    assert np.isnan(bank.episode_error([0, 1], np.ones((2, 2)))[3])  # spread only when asked


def test_episode_error_rejects_what_error_rejects():
    bank = _bank(np.random.default_rng(3))
    Y = np.ones((3, 2))
    with pytest.raises(ValueError, match=r"states must lie in \[0, 30\); got 30"):
        bank.episode_error(np.array([0, 30, 1]), Y)
    with pytest.raises(ValueError, match="Y contains NaN or inf"):
        bank.episode_error(np.array([0, 1, 2]), np.array([[0.0, 1.0], [np.nan, 0.0], [1.0, 1.0]]))
    with pytest.raises(ValueError, match="Y must have 2 features"):
        bank.episode_error([0, 1, 2], np.ones((3, 3)))
