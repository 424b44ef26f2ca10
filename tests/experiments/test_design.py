"""The design of readings (neurocur.experiments.design): each scale by hand, Sobol's balance, the
experiment it writes as the entrance reads it, and the refusals."""

import math
import tomllib

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.experiments.design import design_experiment, draws, read_prior, value_at
from neurocur.results.tomlio import dumps_toml

PRIOR = {"EC.mca_rate": {"log": [0.01, 0.16]}, "PFC.discount": {"linear": [0.5, 0.9]},
         "HPC.drift_ratios": {"int": [1, 3]}, "world.normalise": {"choice": ["global", "image"]},
         "circuit": {"choice": ["vta_state_progress", "cd_misfa"]}, "HPC.ordered": {"choice": [True, False]}}


def test_each_scale_at_hand_made_quantiles():
    assert value_at("log", (0.01, 0.16), 0.5) == pytest.approx(0.04)       # the geometric mean
    assert value_at("log", (0.01, 0.16), 0.25) == pytest.approx(0.02)
    assert value_at("linear", (0.5, 0.9), 0.25) == pytest.approx(0.6)
    assert [value_at("int", (1, 3), u) for u in (0.0, 0.33, 0.34, 0.66, 0.67, 0.999)] == [1, 1, 2, 2, 3, 3]
    assert [value_at("choice", ["a", "b", "c"], u) for u in (0.0, 0.34, 0.99)] == ["a", "b", "c"]


def test_sobol_draws_fill_every_slice_of_every_key_once():
    prior = read_prior(PRIOR)
    points = draws(prior, 32, seed=1)
    u_linear = (np.array([p["PFC.discount"] for p in points]) - 0.5) / 0.4
    assert sorted(np.floor(u_linear * 32).astype(int)) == list(range(32))   # i.i.d. draws: p ~ 32!/32^32
    u_log = np.log(np.array([p["EC.mca_rate"] for p in points]) / 0.01) / math.log(16)
    assert sorted(np.floor(u_log * 32).astype(int)) == list(range(32))
    assert sum(p["world.normalise"] == "image" for p in points) == 16
    assert sum(p["HPC.ordered"] is True for p in points) == 16
    assert points == draws(prior, 32, seed=1) and points != draws(prior, 32, seed=2)


def test_the_experiment_holds_each_draw_where_the_entrance_reads_it(tmp_path):
    prior = read_prior(PRIOR)
    table = design_experiment("synthetic", prior, n=4, runs=3, steps=1000, seed=11, design_seed=5)
    path = tmp_path / "design.toml"
    path.write_text(dumps_toml(table))
    assert tomllib.loads(path.read_text()) == table
    experiment = load_experiment(path)
    assert list(experiment.conditions) == ["d000", "d001", "d002", "d003"]
    assert experiment.runs == 3 and experiment.steps == 1000
    for condition, point in zip(experiment.conditions.values(), draws(prior, 4, seed=5)):
        assert condition.world["normalise"] == point["world.normalise"]
        assert condition.circuit_path.stem == point["circuit"]
        for key in ("EC.mca_rate", "PFC.discount", "HPC.drift_ratios", "HPC.ordered"):
            assert condition.params[key] == point[key]
        assert condition.params["HPC.freeze"] == "converged"                 # synthetic's reading, not drawn


@pytest.mark.parametrize("entry, key", [
    ({"EC.mca_rate": {"log": [0.0, 1.0]}}, "prior.EC.mca_rate.log"),
    ({"EC.mca_rate": {"uniform": [0.1, 1.0]}}, "prior.EC.mca_rate"),
    ({"HPC.drift_ratios": {"int": [1.0, 3]}}, "prior.HPC.drift_ratios.int"),
    ({"PFC.discount": {"linear": [0.9, 0.5]}}, "prior.PFC.discount.linear"),
    ({"world.normalise": {"choice": ["global"]}}, "prior.world.normalise.choice"),
    ({"threshold": {"linear": [0.1, 0.5]}}, "prior.threshold"),
])
def test_a_bad_entry_is_refused_in_one_line_naming_its_key(entry, key):
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        read_prior(entry)


def test_a_design_size_that_breaks_sobols_balance_is_refused():
    with pytest.raises(ConfigError, match="power of two"):
        draws(read_prior(PRIOR), 24, seed=1)
