"""Shared by the results store's tests: a small written results folder, and a copy of it to break."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from neurocur.experiments import load_experiment, run_experiment

SYNTHETIC = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The curious condition's 2 runs of 1000 frames, written once per test module."""
    out = tmp_path_factory.mktemp("written") / "out"
    run_experiment(load_experiment(SYNTHETIC, runs=2, steps=1000), out, jobs=2, conditions=["curious"], progress=False)
    return out


@pytest.fixture
def folder(written, tmp_path):
    """A copy of the written results folder, to break (links copied as links)."""
    return Path(shutil.copytree(written, tmp_path / "out", symlinks=True))
