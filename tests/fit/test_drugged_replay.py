"""Replay of a run with a drug on the decision region: the decision's log-probabilities are those of the
released (drugged) gain, on the vectorised path as on the stepped one.

A ``scale`` drug on LC's released level multiplies the gain the decision reads (:mod:`neurocur.regions.
pharmacology`), so the replayed log-likelihood at the circuit's own gain is the agent's own, computed
from the recorded (released) gain, and at any fitted gain g it is that of factor * g. Evaluated with the
undrugged gain, it would be another number: the factor 0.25 moves it by far more than 1e-9.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.circuit import Circuit
from neurocur.fit.data import behaviour_from_episodes
from neurocur.fit.replay import Replay
from neurocur.regions.lc_softmax import log_p_decision

FACTOR = 0.25


def test_a_drugged_softmax_decision_is_replayed_with_the_released_gain(circuits_dir, small, make_world):
    base = Circuit.from_toml(circuits_dir / "lc_softmax.toml", small).with_params({"LC.gain": 8.0})
    circuit = base.lesion("LC", "scale", factor=FACTOR)
    assert circuit.specs["LC"].cls.log_likelihoods is not None  # the vectorised path a drug must not take
    world = make_world()
    sim = circuit.build(world, seed=5)
    sim.run(60 * world.episode_len)
    episodes = sim.episodes()
    assert len(episodes) == 60
    np.testing.assert_allclose(episodes["ne_gain"], FACTOR * 8.0, rtol=0, atol=1e-12)  # the drug acted
    dq = (episodes["q_disengage"] - episodes["q_engage"]).to_numpy()
    decision = (episodes["action"] == "disengage").to_numpy().astype(np.int64)
    own = log_p_decision(episodes["ne_gain"].to_numpy(), dq, decision)  # the agent's own, as it acted
    undrugged = log_p_decision(8.0, dq, decision)
    assert abs(own.sum() - undrugged.sum()) > 1.0  # the drug matters to the likelihood
    table = pd.DataFrame({"dataset": "run", "episode": episodes["episode"], "context": episodes["context"],
                          "decision": episodes["action"]})
    (behaviour,) = behaviour_from_episodes(table, world.context_names)
    replay = Replay(circuit, make_world(), 5, behaviour, fitted=["LC.gain"])
    np.testing.assert_allclose(replay.logp, own, rtol=0, atol=1e-9)
    assert abs(replay.loglik({"LC.gain": 8.0}) - own.sum()) < 1e-9
    gains = [0.0, 3.0, 8.0, 20.0]
    expected = [log_p_decision(FACTOR * g, dq, decision).sum() for g in gains]
    np.testing.assert_allclose(replay.loglik([{"LC.gain": g} for g in gains]), expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose([replay.episode_logp({"LC.gain": g}).sum() for g in gains], expected, rtol=0, atol=1e-9)


@pytest.mark.parametrize("fitted", [["LC.gain"], ["LC.gain", "LC.stay"]])
def test_a_drugged_free_choice_is_replayed_with_the_released_gain(make_world, fitted):
    """The choice LC: the replayed log-likelihood is the log of the recorded probabilities of the chosen
    contexts, at the circuit's own parameters, as the agent acted with the drugged gain."""
    base = Circuit.from_toml("free_choice", {"LC.gain": 40.0, "PFC.alpha": 0.3})
    circuit = base.lesion("LC", "scale", factor=FACTOR)
    assert circuit.specs["LC"].cls.log_likelihoods is not None
    world = make_world()
    sim = circuit.build(world, seed=11)
    sim.run(80 * world.episode_len)
    episodes = sim.episodes()
    np.testing.assert_allclose(episodes["ne_gain"], FACTOR * 40.0, rtol=0, atol=1e-12)
    table = pd.DataFrame({"dataset": "s", "episode": episodes["episode"], "context": episodes["context"],
                          "decision": episodes["next_context"]})
    (behaviour,) = behaviour_from_episodes(table, world.context_names, free_choice=True)
    replay = Replay(circuit, make_world(), 11, behaviour, fitted=fitted)
    own = np.log(episodes["p_chosen"].to_numpy())
    np.testing.assert_allclose(replay.logp, own, rtol=0, atol=1e-9)
    theta = {k: getattr(circuit.specs["LC"].params, k.split(".")[1]) for k in fitted}
    assert abs(replay.loglik(theta) - own.sum()) < 1e-9
    undrugged = Replay(base, make_world(), 11, behaviour, fitted=fitted)
    assert abs(undrugged.loglik(theta) - own.sum()) > 1.0  # what the gain 40 would have given: far from it
    assert abs(replay.loglik(theta) - replay.episode_logp(theta).sum()) < 1e-9
