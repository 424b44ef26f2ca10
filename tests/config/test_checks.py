"""The public checks of neurocur.config.checks: scalar arguments through ParamSpecs, seeds, data blocks."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.config.checks import (
    check_block,
    check_fraction,
    check_nonconstant,
    check_positive_int,
    check_random_state,
)


def test_positive_int_and_fraction_coerce_and_name_the_argument():
    assert check_positive_int(np.int64(3), "n_steps") == 3 and type(check_positive_int(3, "n")) is int
    assert check_fraction(1, "var_fraction") == 1.0 and check_fraction(0.25, "f") == 0.25
    with pytest.raises(ConfigError, match=r"^sinusoid_pair: key 'n_steps': expected an integer >= 1, got 0 \(int\)$"):
        check_positive_int(0, "n_steps", source="sinusoid_pair")
    for bad in (True, 2.0, "3"):
        with pytest.raises(ConfigError, match="key 'n'"):
            check_positive_int(bad, "n")
    for bad in (0.0, 1.5, float("nan"), "half"):
        with pytest.raises(ConfigError, match=r"key 'var_fraction': expected a number > 0 and <= 1"):
            check_fraction(bad, "var_fraction")


def test_random_state_is_numpy_default_rng_of_a_checked_seed():
    gen = np.random.default_rng(1)
    assert check_random_state(gen) is gen
    for seed in (7, np.int32(7), np.random.SeedSequence(7)):
        np.testing.assert_array_equal(check_random_state(seed).random(3), np.random.default_rng(7).random(3))
    assert isinstance(check_random_state(None), np.random.Generator)
    for bad in (-1, 1.5, "7", True):
        with pytest.raises(ConfigError, match="key 'random_state'"):
            check_random_state(bad)


def test_block_checks_say_what_was_expected():
    out = check_block([[1, 2], [3, 4]])
    assert out.dtype == np.float64 and out.flags.c_contiguous and out.shape == (2, 2)
    cases = [
        (np.array([["a"]]), "must hold real numbers"),
        (np.ones(3), "must be 2-d"),
        (np.ones((0, 2)), "at least 1 row"),
        (np.array([[1.0, np.inf]]), r"contains NaN or inf \(first at row 0, column 1\)"),
    ]
    for X, message in cases:
        with pytest.raises(ValueError, match=message):
            check_block(X)
    with pytest.raises(ValueError, match="Y must have 3 features"):
        check_block(np.ones((2, 2)), name="Y", n_features=3)
    check_nonconstant(np.array([[0.0, 1.0], [0.0, 2.0]]))
    with pytest.raises(ValueError, match="zero variance"):
        check_nonconstant(np.ones((5, 2)))
