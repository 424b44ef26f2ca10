"""The softmax LC (docs/extending.md's worked example): its decision rule, and its circuit file."""

from pathlib import Path

import numpy as np
import pytest
from bound_region import bound, minimal_world

from neurocur.circuit import Circuit
from neurocur.regions.lc_softmax import SoftmaxLC

CIRCUIT = Path(__file__).resolve().parents[2] / "neurocur" / "circuits" / "lc_softmax.toml"


def _lc(gain, seed=0):
    return bound(SoftmaxLC, "LC", world=minimal_world(4), seed=seed, gain=gain)


@pytest.mark.parametrize("gain", [0.0, 0.5, 3.0])
def test_disengage_rate_is_the_logistic_of_the_gain_times_the_advantage(gain):
    lc, q, n = _lc(gain), np.array([0.2, 0.9]), 20_000
    actions = np.array([lc.step(1, q, False)[0] for _ in range(n)])
    p = 1.0 / (1.0 + np.exp(-gain * 0.7))
    assert abs(actions.mean() - p) < 4 * np.sqrt(p * (1 - p) / n)
    assert lc.record()[2] == pytest.approx(p, rel=1e-12)


def test_disengage_goes_uniformly_to_another_context_and_engage_stays():
    lc = _lc(50.0, seed=3)
    nxt = np.array([lc.step(2, np.array([0.0, 1.0]), False)[1] for _ in range(8000)])  # nearly always disengage
    assert 2 not in set(nxt) and np.allclose(np.bincount(nxt, minlength=4)[[0, 1, 3]] / len(nxt), 1 / 3, atol=0.02)
    assert {lc.step(2, np.array([1.0, 0.0]), False)[1] for _ in range(200)} == {2}


def test_circuit_file_swaps_the_lc_and_records_ne():
    from neurocur.contexts.synthetic import SyntheticWorld

    circuit = Circuit.from_toml(CIRCUIT, overrides={"HPC.n_states": 1000})
    assert circuit.specs["LC"].type_name == "lc.softmax" and circuit.specs["LC"].params.gain == 1.0
    episodes = circuit.build(SyntheticWorld(), seed=1).run(5000).episodes()
    assert {"ne_tonic", "ne_phasic", "action", "next_context"} <= set(episodes.columns)
    assert episodes["ne_tonic"].between(0.0, 1.0).all() and "epsilon" not in episodes
