"""The free choice among N contexts, and signal replay of a recorded error in HPC's place."""

from __future__ import annotations

import numpy as np
import pandas as pd

from neurocur.circuit import Circuit
from neurocur.fit.data import behaviour_from_episodes
from neurocur.fit.replay import Replay, signal_circuit
from neurocur.regions.lc_choice import choice_probabilities


def test_choice_probabilities_are_a_softmax_with_a_stay_bonus():
    p = choice_probabilities(2.0, [0.0, 1.0, 0.5], 0, 0.25)
    z = np.exp(2.0 * np.array([0.25, 1.0, 0.5]))
    np.testing.assert_allclose(p, z / z.sum(), rtol=1e-14)
    np.testing.assert_allclose(choice_probabilities(0.0, [3.0, -1.0, 9.0], 1, 5.0), [1 / 3] * 3)
    assert np.isfinite(choice_probabilities(1e6, [0.0, 1.0, 0.5], 0, 0.0)).all()


def test_signal_replay_scores_the_choices_the_agent_made(make_world):
    circuit = Circuit.from_toml("free_choice", {"LC.gain": 40.0, "PFC.alpha": 0.3})
    world = make_world()
    sim = circuit.build(world, seed=11)
    sim.run(80 * world.episode_len)
    episodes = sim.episodes()
    assert len(episodes) == 80 and episodes["next_context"].nunique() == 3  # it samples every task
    table = pd.DataFrame({"dataset": "s", "episode": episodes["episode"], "context": episodes["context"],
                          "decision": episodes["next_context"], "error": episodes["error"]})
    (behaviour,) = behaviour_from_episodes(table, world.context_names, free_choice=True, signals=["error"])
    recorded = signal_circuit(circuit, "HPC", behaviour, "error")
    assert recorded.specs["HPC"].type_name == "signal.recorded"
    replay = Replay(recorded, make_world(), 99, behaviour, fitted=["LC.gain", "PFC.alpha"])
    expected = np.log(episodes["p_chosen"]).sum()
    assert abs(replay.logp.sum() - expected) < 1e-9
    assert abs(replay.loglik({"LC.gain": 40.0, "PFC.alpha": 0.3}) - expected) < 1e-9
    # the vectorised choice likelihood equals the stepped one at other gains
    gains = Replay(recorded, make_world(), 99, behaviour, fitted=["LC.gain", "LC.stay"])
    thetas = [{"LC.gain": g, "LC.stay": s} for g, s in ((0.0, 0.0), (10.0, 0.1), (80.0, -0.2))]
    np.testing.assert_allclose(gains.loglik(thetas), [gains.episode_logp(t).sum() for t in thetas], atol=1e-9)
    assert abs(gains.loglik(thetas[0]) - 80 * np.log(1 / 3)) < 1e-9
