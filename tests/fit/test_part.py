"""The decision part (neurocur.fit.part) of the bandit's circuit: which regions a cached replay steps again, and
the circuits it refuses (a fitted region off the way to the decision, the clock on the way, not a decision region)."""

from __future__ import annotations

import pytest

from neurocur.circuit import Circuit, Link
from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.fit.part import decision_part, observed_outputs


@pytest.fixture(scope="module")
def circuit():
    """sensory (the clock) -> PFC (values, delayed) -> LC (not delayed) -> sensory (the choice, not delayed)."""
    return load_experiment("bandit").conditions["delta"].circuit


def test_the_part_is_the_fitted_regions_on_the_way_to_the_decision_in_step_order(circuit):
    assert decision_part(circuit, "LC", []) == ("LC",)
    assert decision_part(circuit, "LC", ["LC.beta"]) == ("LC",)
    assert decision_part(circuit, "LC", ["LC.beta", "PFC.alpha"]) == ("PFC", "LC")
    assert observed_outputs(circuit, "LC") == ("action", "next_context")
    # the observed decision may feed the learning part (a delayed edge into PFC): PFC stays out of the part
    links = [k for k in circuit.links if str(k) != "sensory.context -> PFC.chosen"]
    looped = Circuit(circuit.specs, [*links, Link("LC", "next_context", "PFC", "chosen", delayed=True)])
    assert decision_part(looped, "LC", ["LC.beta"]) == ("LC",)


def test_a_region_that_does_not_reach_the_decision_or_is_not_there_is_refused(circuit):
    with pytest.raises(ConfigError, match="key 'sensory.x': expected a parameter of a region on the way to the "
                                          r"decision \('LC'\)"):
        decision_part(circuit, "LC", ["sensory.x"])
    with pytest.raises(ConfigError, match="key 'HPC.x': expected REGION.param with a region of the circuit"):
        decision_part(circuit, "LC", ["HPC.x"])
    with pytest.raises(ConfigError, match="key 'decision': expected a region of the circuit"):
        decision_part(circuit, "XX", [])
    with pytest.raises(ConfigError, match="key 'regions.PFC': expected a decision region"):
        decision_part(circuit, "PFC", ["PFC.alpha"])


def test_a_decision_part_through_the_clock_is_refused(circuit):
    """A task that pays the previous trial's choice before PFC steps (not delayed): the clock is on the way from
    its parameters to the decision, and the replay, which counts passes, not the clock's frames, refuses it."""
    links = [Link("PFC", "values", "LC", "values"), Link("LC", "next_context", "sensory", "choice", delayed=True),
             Link("sensory", "context", "PFC", "chosen"), Link("sensory", "reward", "PFC", "outcome"),
             Link("sensory", "context", "LC", "context", delayed=True)]
    with pytest.raises(ConfigError, match="clock region 'sensory'"):
        decision_part(Circuit(circuit.specs, links), "LC", ["sensory.anything"])
