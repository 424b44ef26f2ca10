"""Fixtures of hand-made results folders (:mod:`fake_runs`), independent of the simulator."""

from __future__ import annotations

import pytest
from fake_runs import CURIOUS, CYCLE, PFC_ALPHA, RANDOM, make_run, write_results


@pytest.fixture(scope="session")
def results_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp("results") / "synthetic"
    runs = {
        "curious": [make_run(CYCLE, stored, seed=i) for i, stored in enumerate(CURIOUS)],
        "random_switching": [make_run(CYCLE, stored, seed=10 + i) for i, stored in enumerate(RANDOM)],
    }
    return write_results(root, runs)


@pytest.fixture(scope="session")
def study_dir(tmp_path_factory):
    """A reproduction-study folder: ``default``, its random-switching twin ``default_random``,
    and ``alpha_005`` (the same runs as ``default``; it shares default's twin)."""
    curious = [make_run(CYCLE, stored, seed=i) for i, stored in enumerate(CURIOUS)]
    runs = {"default": curious, "alpha_005": curious,
            "default_random": [make_run(CYCLE, stored, seed=10 + i) for i, stored in enumerate(RANDOM)]}
    return write_results(tmp_path_factory.mktemp("study") / "reproduction", runs, alphas={}, control=None)


@pytest.fixture(scope="session")
def pfc_alpha():
    """The PFC ``alpha`` of each condition, as the results folder's config.toml records it."""
    return dict(PFC_ALPHA)


@pytest.fixture(scope="session")
def tables(results_dir):
    from neurocur.analysis import load

    return load(results_dir)


@pytest.fixture(scope="session")
def results(results_dir):
    from neurocur.analysis import Results

    return Results.load(results_dir)


@pytest.fixture(scope="session")
def write_folder():
    """:func:`fake_runs.write_results`, to write a folder of one's own."""
    return write_results
