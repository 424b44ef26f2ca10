"""Fixtures shared by the fit layer's tests."""

from __future__ import annotations

import pytest

from neurocur.experiments import load_experiment, run_experiment


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A results folder of one short free-choice run."""
    out = tmp_path_factory.mktemp("results") / "free_choice"
    run_experiment(load_experiment("free_choice", runs=1, steps=60), out, jobs=1, conditions=["learning_progress"],
                   progress=False)
    return out
