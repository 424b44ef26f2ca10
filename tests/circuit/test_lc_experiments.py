"""Every LC model beside the paper's (whose runs the experiments' own tests cover) in short runs of the
synthetic and the iCub experiments, through the runner: the recorded decisions, NE and contract columns."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from neurocur.circuit import Circuit
from neurocur.contract import EPISODE_COLUMNS
from neurocur.experiments import run_one

#: the shipped circuit of each LC model beside the paper's
LC_CIRCUITS = {"lc.softmax": "lc_softmax", "lc.adaptive_gain": "lc_adaptive_gain", "lc.fhn": "lc_fhn"}


def _with_lc(experiment, type_name):
    """The experiment's curious condition with the LC model's circuit (the experiment's LC parameters dropped)."""
    cond = experiment.conditions["curious"]
    params = {k: v for k, v in cond.params.items() if not k.startswith("LC.")}
    return dataclasses.replace(cond, circuit=Circuit.from_toml(LC_CIRCUITS[type_name], overrides=params))


def _check(episodes):
    assert {c.name for c in EPISODE_COLUMNS} <= set(episodes.columns)
    assert episodes["ne_tonic"].between(0, 1).all() and episodes["ne_phasic"].between(0, 1).all()
    stay = episodes["action"] == "engage"
    np.testing.assert_array_equal(episodes["next_context"][stay], episodes["context"][stay])
    assert (episodes["next_context"][~stay] != episodes["context"][~stay]).all()
    gain = episodes["ne_gain"].to_numpy()
    assert np.isfinite(gain).all() and (gain >= 0).all()


@pytest.fixture(scope="module")
def synthetic(short_experiment):
    return short_experiment("synthetic", 5000)


@pytest.mark.parametrize("type_name", LC_CIRCUITS)
def test_every_lc_model_runs_in_the_synthetic_experiment(synthetic, type_name):
    result = run_one(_with_lc(synthetic, type_name), 1, synthetic.steps, synthetic.run_seed(1))
    episodes = result.episodes
    assert episodes["module_learned"].any() and len(result.modules) == episodes["module_learned"].sum()
    _check(episodes)


@pytest.fixture(scope="module")
def icub(short_experiment):
    return short_experiment("icub", 1500)


@pytest.mark.parametrize("type_name", LC_CIRCUITS)
def test_every_lc_model_runs_in_the_icub_experiment(icub, type_name):
    episodes = run_one(_with_lc(icub, type_name), 0, icub.steps, icub.run_seed(0)).episodes
    assert episodes["module_learned"].any() and set(episodes["context"]) <= {0, 1}
    _check(episodes)
