"""Shared by the world tests: gymnasium's env checker, strictly."""

from __future__ import annotations

import warnings

import pytest
from gymnasium.utils.env_checker import check_env

NO_SPEC = "Not able to test alternative render modes due to the environment not having a spec"


def _check_env_strictly(env) -> None:
    """gymnasium's check_env, and no warning but the one that an env not made by gymnasium.make has no spec."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env)
    assert [str(w.message) for w in caught if NO_SPEC not in str(w.message)] == []


@pytest.fixture
def check_env_strictly():
    return _check_env_strictly
