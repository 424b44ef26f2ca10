"""Parameter and model recovery on small simulated data sets, and the confusion matrix's arithmetic."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.circuit import Circuit
from neurocur.fit.recovery import (
    confusion,
    confusion_figure,
    model_recovery,
    parameter_recovery,
    recovery_figure,
    recovery_summary,
)


class Condition:
    """What recovery needs of an experiment condition: a circuit and a world."""

    def __init__(self, circuit, world):
        self.circuit, self.world = circuit, world

    def make_world(self):
        return self.world()


@pytest.fixture
def free_choice(make_world):
    return Condition(Circuit.from_toml("free_choice", {"PFC.alpha": 0.3}), make_world)


def test_the_choice_gain_is_recovered_on_simulated_free_choices(free_choice):
    table = parameter_recovery(free_choice, {"LC.gain": (1.0, 60.0)}, n_datasets=6, n_episodes=150, seed=1,
                               starts=2, signal=("HPC", "error"))
    summary = recovery_summary(table)
    assert list(table.columns) == ["dataset", "param", "true", "estimate", "ci_low", "ci_high", "loglik"]
    row = summary.iloc[0]
    assert row["n"] == 6 and row["r"] > 0.8 and row["coverage"] >= 0.5
    assert (table["ci_low"] <= table["estimate"]).all() and (table["estimate"] <= table["ci_high"]).all()
    assert recovery_figure(table).axes


def test_confusion_counts_winners_and_shares_ties():
    table = pd.DataFrame({"generating": ["a"] * 4 + ["b"] * 4, "dataset": ["a/0", "a/0", "a/1", "a/1",
                                                                          "b/0", "b/0", "b/1", "b/1"],
                          "fitted": ["a", "b"] * 4, "aic": [1.0, 2.0, 5.0, 5.0, 3.0, 1.0, 4.0, 2.0],
                          "heldout": [-1.0, -2.0, -3.0, -1.0, -5.0, -1.0, -2.0, -1.0]})
    np.testing.assert_allclose(confusion(table, "aic").to_numpy(), [[0.75, 0.25], [0.0, 1.0]])
    np.testing.assert_allclose(confusion(table, "heldout").to_numpy(), [[0.5, 0.5], [0.0, 1.0]])


def test_model_recovery_tells_a_learner_from_random_choice(free_choice, make_world):
    random = Condition(free_choice.circuit.with_params({"LC.gain": 0.0}), make_world)
    table = model_recovery({"learner": free_choice, "random": random},
                           {"learner": {"LC.gain": (20.0, 60.0)}, "random": {}}, n_datasets=3, n_episodes=120, seed=2)
    assert len(table) == 2 * 3 * 2
    by_bic = confusion(table, "bic")
    assert by_bic.loc["learner", "learner"] == 1.0 and by_bic.loc["random", "random"] == 1.0
    r = table[(table["fitted"] == "random")]
    np.testing.assert_allclose(r["loglik"], 120 * np.log(1 / 3))  # no free parameter: a uniform choice of 3
    assert confusion_figure(table).axes
