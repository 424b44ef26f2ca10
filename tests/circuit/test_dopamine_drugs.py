"""A drug on the released dopamine, against what the equations say it can change (docs/hypotheses.md,
entry 8): PFC's reward model and LSPI are linear in DA, so a DA scale f scales every Q value by f.
The paper's epsilon-greedy LC reads only the sign of Q_dis - Q_eng, so f > 0 changes no decision and
a block (f = 0) makes every greedy decision a tie, broken by the draws the random-switching lesion
makes; the softmax LC reads gain x (Q_dis - Q_eng), so DA x f is the gain x f."""

import numpy as np
import pytest

from neurocur.circuit import Circuit

FRAMES = 6000


def _run(circuit, world, seed):
    return circuit.build(world(), seed=seed).run(FRAMES).episodes()


@pytest.mark.parametrize("seed", [0, 1])
def test_a_da_scale_changes_no_decision_of_the_epsilon_greedy_agent_and_a_block_is_random_switching(
        seed, circuits_dir, small, make_world):
    circuit = Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides=small)
    reference = _run(circuit, make_world, seed)
    assert reference["module_learned"].any() and (reference["q_engage"] != reference["q_disengage"]).mean() > 0.5
    for factor in (0.25, 4.0):
        drugged = _run(circuit.lesion("VTA", "scale", factor=factor), make_world, seed)
        assert drugged[["context", "action", "module_learned"]].equals(reference[["context", "action", "module_learned"]])
        np.testing.assert_allclose(drugged["da"], factor * reference["da"], rtol=1e-12)  # the drug did act
    blocked = _run(circuit.lesion("VTA", "scale", factor=0.0), make_world, seed)
    random = _run(circuit.lesion("LC", "random"), make_world, seed)
    assert blocked[["context", "action"]].equals(random[["context", "action"]])
    assert not blocked[["context", "action"]].equals(reference[["context", "action"]])


@pytest.mark.parametrize("factor", [0.25, 4.0])
def test_a_da_scale_on_the_softmax_agent_is_its_gain(factor, circuits_dir, small, make_world):
    circuit = Circuit.from_toml(circuits_dir / "lc_softmax.toml", overrides=small)
    drugged = _run(circuit.lesion("VTA", "scale", factor=factor), make_world, 4)
    gained = _run(circuit.with_params({"LC.gain": factor}), make_world, 4)
    assert drugged[["context", "action", "module_learned"]].equals(gained[["context", "action", "module_learned"]])
    assert not drugged[["context", "action"]].equals(_run(circuit, make_world, 4)[["context", "action"]])
