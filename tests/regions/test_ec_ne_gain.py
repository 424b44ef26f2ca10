"""NE-gated plasticity of EC (docs/regions.md, EC: ``ne_gain``): the MCA rate eta (1 + k NE) is
the rate the learner uses, off by default with no ``ne`` input, and the shipped circuit that wires
it closes its loop through a delayed edge."""

import numpy as np
import pytest
from bound_region import bound

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.regions.ec import ECIncSFA, ECParams, ne_rate


def test_ne_rate_scales_the_mca_rate_and_is_capped():
    p = ECParams(mca_rate=0.05, ne_gain=4.0)
    assert ne_rate(p, 0.5) == pytest.approx(0.15)
    assert ne_rate(p, None) == 0.05 and ne_rate(p, -1.0) == 0.05  # first pass; a negative level counts as 0
    assert ne_rate(ECParams(mca_rate=0.2, ne_gain=4.0), 1.0) == 0.5


def test_default_ec_reads_no_ne():
    assert [s.name for s in ECIncSFA("EC").learn_inputs] == ["familiar", "module_learned"]
    assert [s.name for s in ECIncSFA("EC", ne_gain=1.0).learn_inputs] == ["familiar", "module_learned", "ne"]


def _projection(world_seed, episodes, **params):
    world = SyntheticWorld(["S-A", "S-B"], visit_length=50, frame_shape=(4, 4))
    world.reset(seed=world_seed)
    ec = bound(ECIncSFA, "EC", world=world, seed=3, **params)
    for i in range(episodes):
        ec.step(world.step(i % 2)[0])
        ec.learn(False, False, *([0.5] if params.get("ne_gain") else []))
    return ec.adaptive.projection_


def test_the_gated_learner_learns_at_the_gated_rate():
    gated = _projection(1, 30, mca_rate=0.05, ne_gain=4.0)
    np.testing.assert_allclose(gated, _projection(1, 30, mca_rate=0.15), rtol=0, atol=1e-12)
    assert not np.allclose(gated, _projection(1, 30, mca_rate=0.05), atol=1e-6)


def test_ne_plasticity_circuit_closes_the_loop_through_a_delayed_edge(circuits_dir):
    circuit = Circuit.from_toml(circuits_dir / "ne_plasticity.toml")
    assert "  LC.ne -> EC.ne" in circuit.schedule().split("learn-phase edges")[0]
    assert circuit.specs["EC"].params.ne_gain == 4.0
    assert Circuit.from_toml(circuits_dir / "cd_misfa.toml").specs["EC"].params.ne_gain == 0.0
    sim = circuit.build(SyntheticWorld(visit_length=50, frame_shape=(4, 4)), seed=2).run(3000)
    assert len(sim.episodes()) > 10
