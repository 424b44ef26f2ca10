"""The PFC's reward model replayed from recorded DA and decisions (docs/reproduction.md 2.8)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from neuro_tables import results_of

from neurocur.analysis import Results
from neurocur.analysis.stats.reward_model import decision_rewards, replay_reward_model
from neurocur.contexts.base import SourceSpec
from neurocur.regions.pfc import ACTIONS, PFCLSPI, transition_model

NO_MODULES = pd.DataFrame({"condition": pd.Series(dtype=object), "run": pd.Series(dtype=int)})


@pytest.mark.parametrize("alpha", [0.3, "sample_average"])
def test_the_replay_is_the_pfcs_own_model_bit_for_bit(alpha):
    rng = np.random.default_rng(5)
    n, steps = 4, 80
    contexts, actions, da = rng.integers(n, size=steps), rng.integers(2, size=steps), rng.normal(size=steps)
    pfc = PFCLSPI(alpha=alpha)
    pfc.bind(SimpleNamespace(n_contexts=n))
    pfc.reset(np.random.default_rng(0))
    P, own = transition_model(n), []
    for t in range(steps):
        pfc.step(int(contexts[t]), float(da[t]), None if t == 0 else int(actions[t - 1]))
        own.append(np.einsum("oas,oas->oa", P, pfc.model.R3))
    run = pd.DataFrame({"context": contexts, "da": da, "action": [ACTIONS[a] for a in actions]})
    np.testing.assert_array_equal(replay_reward_model(run, n, alpha), np.array(own))


def test_decision_rewards_by_hand():
    # two contexts, alpha 0.5; decisions: engage, disengage, engage, disengage
    run = pd.DataFrame({"condition": "c", "run": 0, "episode": [0, 1, 2, 3], "context": [0, 0, 1, 1],
                        "da": [9.0, 2.0, 4.0, -2.0], "action": ["engage", "disengage", "engage", "disengage"],
                        "q_engage": [0.0, 1.0, 0.0, 0.0], "q_disengage": [0.0, 0.0, 1.0, 1.0]})
    # R[0, eng, 0] = 1 after episode 1; R[0, dis, 1] = 2 after 2; R[1, eng, 1] = -1 after 3
    two = SourceSpec(("C1", "C2"), ("S-A", "S-B"), ("S-A", "S-B"))
    row = decision_rewards(results_of(run, NO_MODULES, two), 0.5).iloc[0]
    assert row["da_after_engage"] == pytest.approx(0.0) and row["da_after_disengage"] == 4.0
    # the current context's R(o, .) at each decision: (0, 0), (1, 0), (0, 0), (-1, 0)
    assert row["r_engage"] == 0.0 and row["r_disengage"] == 0.0
    assert row["engage_below"] == 0.25 and row["greedy_disengage"] == 0.5
    first = decision_rewards(results_of(run, NO_MODULES, {"c": two}), {"c": 0.5}, last_episode=pd.Series({("c", 0): 1})).iloc[0]
    assert first["n_decisions"] == 2 and first["da_after_disengage"] != first["da_after_disengage"]  # NaN: none
    assert decision_rewards(results_of(run, NO_MODULES, two), 0.5, last_episode=pd.Series({("c", 1): 1}, dtype=float)).empty


def test_the_model_is_sized_by_the_world_not_by_the_contexts_visited():
    """A disengage spreads over every other context of the world (eqs 12-13), visited or not."""
    run = pd.DataFrame({"condition": "c", "run": 0, "episode": [0, 1, 2], "context": [0, 1, 0], "da": [0.0, 4.0, 2.0],
                        "action": ["disengage", "disengage", "engage"], "q_engage": 0.0, "q_disengage": 0.0})
    two = SourceSpec(("C1", "C2"), ("S-A", "S-B"), ("S-A",))
    three = SourceSpec(("C1", "C2", "C3"), ("S-A", "S-B", "S-C"), ("S-A",))
    # R[0, dis, 1] = 2 after episode 1; at episode 2 (in C1) R(C1, disengage) = 2 / (contexts - 1)
    assert decision_rewards(results_of(run, NO_MODULES, two), 0.5).iloc[0]["r_disengage"] == pytest.approx(2 / 3)
    assert decision_rewards(results_of(run, NO_MODULES, three), 0.5).iloc[0]["r_disengage"] == pytest.approx(1 / 3)


def test_by_default_each_condition_replays_its_own_value_estimators_alpha(write_folder, tmp_path):
    """The rate is read from each condition's region of the value estimator's type, whatever its name."""
    run = pd.DataFrame({"episode": [0, 1, 2, 3], "step": [0, 100, 200, 300], "n_frames": 100, "context": [0, 0, 1, 1],
                        "da": [9.0, 2.0, 4.0, 2.0], "action": ["engage", "disengage", "engage", "disengage"],
                        "q_engage": 0.0, "q_disengage": 0.0})
    modules = pd.DataFrame({"module": pd.Series(dtype=int), "source": pd.Series(dtype=object)})
    folder = write_folder(tmp_path / "alphas", {"a": [(run, modules)], "b": [(run, modules)]}, alphas={"a": 0.5, "b": 1.0})
    rows = decision_rewards(Results.load(folder)).set_index("condition")
    # R(o, engage) at the four decisions: 0, 2 alpha (R[0, eng, 0]), 0, 2 alpha (R[1, eng, 1]): mean alpha
    assert rows.loc["a", "r_engage"] == pytest.approx(0.5) and rows.loc["b", "r_engage"] == pytest.approx(1.0)
