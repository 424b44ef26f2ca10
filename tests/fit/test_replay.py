"""Replay scores an agent's own decisions with the probabilities it acted on (exact to 1e-9)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.circuit import Circuit
from neurocur.fit.data import behaviour_from_episodes
from neurocur.fit.replay import Replay


def simulate(circuit, world, seed, n):
    sim = circuit.build(world, seed=seed)
    for _ in range(n):
        sim.run(1)
    return sim.episodes()


def as_behaviour(episodes, names, name="run"):
    table = pd.DataFrame({"dataset": name, "episode": episodes["episode"], "context": episodes["context"],
                          "decision": episodes["action"]})
    return behaviour_from_episodes(table, names)[0]


@pytest.fixture
def lc_circuit(circuits_dir, small):
    def make(lc):
        if lc["type"] in ("lc.adaptive_gain", "lc.fhn"):  # their shipped circuits (adaptive gain reads VTA's DA)
            return Circuit.from_toml(circuits_dir / f"{lc['type'].replace('.', '_')}.toml", small)
        return Circuit.from_toml(circuits_dir / "cd_misfa.toml", small).replace("LC", lc)
    return make


@pytest.mark.parametrize("lc,p_dis", [
    ({"type": "lc.epsilon_greedy", "params": {"epsilon0": 0.6, "decay": 0.99}}, lambda e: e["ne_tonic"]),
    ({"type": "lc.softmax", "params": {"gain": 2.0}}, None),
    ({"type": "lc.adaptive_gain", "params": {}}, None),
    ({"type": "lc.fhn", "params": {}}, None),
])
def test_replay_equals_the_agents_own_log_probabilities(lc_circuit, make_world, lc, p_dis):
    circuit = lc_circuit(lc)
    world = make_world()
    episodes = simulate(circuit, world, 7, 60)
    if p_dis is None:  # the gain models: P(disengage) = sigma(gain (Q_dis - Q_eng)) from the recorded gain and Q
        dq = episodes["q_disengage"] - episodes["q_engage"]
        p = 0.5 * (1 + np.tanh(0.5 * episodes["ne_gain"] * dq))
    else:
        p = p_dis(episodes)
    acted = np.where(episodes["action"] == "disengage", p, 1 - p)
    expected = np.log(acted).sum()
    replay = Replay(circuit, make_world(), 7, as_behaviour(episodes, world.context_names))
    assert len(replay.logp) == 60
    assert abs(replay.logp.sum() - expected) < 1e-9
    assert abs(replay.loglik({}) - expected) < 1e-9
    # the replayed run is the run: same contexts, same Q values
    pd.testing.assert_series_equal(replay.episodes["q_engage"], episodes["q_engage"])


def test_cached_decision_part_matches_a_fresh_replay(lc_circuit, make_world):
    """Evaluating theta on the cached inputs equals replaying a circuit built with theta."""
    circuit = lc_circuit({"type": "lc.softmax", "params": {"gain": 2.0}})
    world = make_world()
    behaviour = as_behaviour(simulate(circuit, world, 3, 50), world.context_names)
    replay = Replay(circuit, make_world(), 3, behaviour, fitted=["LC.gain", "PFC.alpha"])
    assert replay.part == ("PFC", "LC")
    theta = {"LC.gain": 0.7, "PFC.alpha": 0.5}
    fresh = Replay(circuit.with_params(theta), make_world(), 3, behaviour)
    assert abs(replay.loglik(theta) - fresh.logp.sum()) < 1e-9
    assert abs(replay.episode_logp(theta).sum() - fresh.logp.sum()) < 1e-9  # the stepped reference too
    several = [{"LC.gain": g, "PFC.alpha": a} for a in (0.5, 0.9) for g in (0.3, 2.0)]
    np.testing.assert_allclose(replay.loglik(several), [replay.episode_logp(t).sum() for t in several], atol=1e-9)
    # the vectorised gain path equals the stepped one
    only_gain = Replay(circuit, make_world(), 3, behaviour, fitted=["LC.gain"])
    gains = [{"LC.gain": g} for g in (0.0, 0.5, 3.0)]
    stepped = np.array([only_gain.episode_logp(t).sum() for t in gains])
    np.testing.assert_allclose(only_gain.loglik(gains), stepped, rtol=0, atol=1e-9)
    assert abs(only_gain.loglik({"LC.gain": 0.0}) - 50 * np.log(0.5)) < 1e-9


def test_a_softmax_decision_far_in_the_tail_keeps_its_log_probability(lc_circuit, make_world):
    """At a gain where sigma rounds to 0 or 1, log P is still log sigma(+-gain dq) (no -inf): the analytic
    log(1 + exp(-x)) of every episode, from the replayed Q values."""
    circuit = lc_circuit({"type": "lc.softmax", "params": {"gain": 2.0}})
    world = make_world()
    episodes = simulate(circuit, world, 3, 50)
    replay = Replay(circuit, make_world(), 3, as_behaviour(episodes, world.context_names), fitted=["LC.gain"])
    gain = 1e4
    dq = (episodes["q_disengage"] - episodes["q_engage"]).to_numpy()
    x = np.where(episodes["action"] == "disengage", 1.0, -1.0) * gain * dq
    assert (np.abs(x) > 80).sum() >= 10  # beyond where sigma rounds to 0 or 1
    expected = -np.logaddexp(0.0, -x).sum()
    assert -np.inf < expected < -100  # some decisions went against Q: the old rounding made them -inf
    assert abs(replay.loglik({"LC.gain": gain}) - expected) < 1e-9 * abs(expected)
    assert abs(replay.episode_logp({"LC.gain": gain}).sum() - expected) < 1e-9 * abs(expected)


def test_a_decision_of_probability_zero_is_minus_infinity_with_its_episode(lc_circuit, make_world):
    circuit = lc_circuit({"type": "lc.epsilon_greedy", "params": {"epsilon0": 0.5, "decay": 0.9}})
    world = make_world()
    episodes = simulate(circuit, world, 5, 40)
    behaviour = as_behaviour(episodes, world.context_names)
    replay = Replay(circuit, make_world(), 5, behaviour, fitted=["LC.epsilon0"])
    logp = replay.episode_logp({"LC.epsilon0": 0.0})
    total = replay.loglik({"LC.epsilon0": 0.0})
    assert not np.isnan(logp).any()
    assert total == -np.inf
    t = int(np.flatnonzero(np.isneginf(logp))[0])
    assert f"episode {t}" in replay.first_impossible(logp)


def test_the_fitzhugh_nagumo_lc_says_it_has_no_closed_form(lc_circuit, make_world):
    """Its probability is exact in a replay, integrated again for each theta (no vectorised path)."""
    from neurocur.regions.lc_fhn import FHNLC
    from neurocur.regions.lc_softmax import SoftmaxLC

    assert FHNLC.closed_form is False and SoftmaxLC.closed_form is True
    circuit = lc_circuit({"type": "lc.fhn"})
    world = make_world()
    behaviour = as_behaviour(simulate(circuit, world, 4, 30), world.context_names)
    replay = Replay(circuit, make_world(), 4, behaviour, fitted=["LC.gain_scale"])
    fresh = Replay(circuit.with_params({"LC.gain_scale": 6.0}), make_world(), 4, behaviour)
    assert abs(replay.loglik({"LC.gain_scale": 6.0}) - fresh.logp.sum()) < 1e-9
