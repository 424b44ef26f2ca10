"""Results: what the analysis knows about an experiment comes from the results folder, not from names."""

from __future__ import annotations

import pytest
from neuro_tables import episodes_of, modules_of, runs_of

from neurocur.analysis import Results, SourceSpec
from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.regions.hpc import HPCROC, HPCParams
from neurocur.regions.pfc import PFCLSPI

SYNTHETIC_TOML = "synthetic"


def test_the_declared_control_reaches_config_toml_and_the_results():
    config = load_experiment(SYNTHETIC_TOML, runs=1, steps=100).resolved()
    assert config["control"] == "random_switching"
    results = Results.of(*runs_of([(episodes_of([0]), modules_of([]))]), SourceSpec(("C1",), ("S-A",), ("S-A",)),
                         config)
    assert results.control == "random_switching"
    assert results.reference == "curious"  # the experiment's first condition


def test_a_control_that_is_not_a_condition_is_named(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('extends = "synthetic"\ncontrol = "lesion"\n')
    with pytest.raises(ConfigError, match="control.*one of the conditions curious, random_switching, literal"):
        load_experiment(path)
    path.write_text('extends = "synthetic"\n')  # the control comes with the conditions it names
    assert load_experiment(path).control == "random_switching"
    path.write_text('extends = "synthetic"\ncontrol = "literal"\n')
    assert load_experiment(path).control == "literal"
    path.write_text('extends = "synthetic"\n[conditions.alone]\n')
    assert load_experiment(path).control is None
    assert "control" not in load_experiment(path, runs=1).resolved()


def test_region_params_are_read_by_region_type_whatever_the_regions_name():
    config = {"conditions": {
        "a": {"resolved_circuit": {"regions": {"Value": {"type": "pfc.lspi", "params": {"alpha": 0.05}},
                                               "Memory": {"type": "hpc.roc", "params": {}}}}},
        "b": {"resolved_circuit": {"regions": {"PFC": {"type": "pfc.lspi", "params": {"alpha": "sample_average"}}}}},
        "c": {"resolved_circuit": {"regions": {"LC": {"type": "lc.random"}}}},
    }}
    results = Results.of(*runs_of([(episodes_of([0]), modules_of([]))]), SourceSpec(("C1",), ("S-A",), ("S-A",)),
                         config)
    assert results.region_param(PFCLSPI, "alpha") == {"a": 0.05, "b": "sample_average"}  # c has none
    assert results.region_param(HPCROC, "threshold") == {"a": HPCParams().threshold}      # not recorded: the default


def test_one_spec_is_asked_only_of_conditions_of_one_world():
    two = SourceSpec(("C1", "C2"), ("S-A", "S-B"), ("S-A", "S-B"))
    one = SourceSpec(("C1",), ("S-A",), ("S-A",))
    tables = runs_of([(episodes_of([0], condition="x"), modules_of([], condition="x")),
                      (episodes_of([0], condition="y"), modules_of([], condition="y"))])
    results = Results.of(*tables, {"x": two, "y": one})
    with pytest.raises(ValueError, match="different sources"):
        assert results.spec is None  # never reached
    assert results.select(["y"]).spec == one and results.spec_of("x") == two
