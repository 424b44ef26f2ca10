"""The signatures of Yu & Dayan (2005, Neuron 46:681) on small runs of the shipped experiment
``yu_dayan2005`` (docs/validation.md, section 4), paired by seed across the drug conditions: the
validity effect grows with the validity; NE rises after an unsignalled change of the relevant cue and
the observer switches to the new cue; ACh depletion and NE depletion act in opposite directions
(ACh depletion: a larger validity effect and more switches, false ones included; NE depletion: fewer
switches and a slow adaptation to a change), and each impairs the prediction of the target."""

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.posner import posner_by_validity, posner_per_run, with_blocks
from neurocur.experiments import load_experiment
from neurocur.experiments.run import run_one


def _episodes(steps, *sets, runs, conditions=None):
    exp = load_experiment("yu_dayan2005", sets=list(sets))
    tables = [run_one(c, r, steps, np.random.SeedSequence(7, spawn_key=(r,))).episodes
              for c in exp.select(conditions) for r in range(runs)]
    return pd.concat(tables, ignore_index=True)


@pytest.fixture(scope="module")
def episodes():
    return _episodes(2000, runs=3)  # 6 conditions x 3 paired runs x 8 blocks of 250 trials


@pytest.fixture(scope="module")
def per_run(episodes):
    return posner_per_run(episodes).set_index(["condition", "run"])


def test_the_validity_effect_grows_with_the_validity(episodes):
    control = posner_by_validity(episodes[episodes["condition"] == "control"])
    effect = control.groupby("validity")["validity_effect"].mean()
    assert list(effect.index) == [0.65, 0.75, 0.85, 0.95]
    assert all(b > a + 0.5 for a, b in zip(effect, effect.iloc[1:])), effect
    assert effect[0.95] > 3 * effect[0.65]
    ach = control.groupby("validity")["ach"].mean()  # ACh falls with the validity, near 1 - validity
    assert all(b < a for a, b in zip(ach, ach.iloc[1:])) and (abs(ach - (1 - ach.index)) < 0.06).all(), ach


def test_ach_depletion_enlarges_the_validity_effect_and_ach_boost_shrinks_it(per_run):
    control, depleted, boosted = (per_run.loc[c] for c in ("control", "ach_depleted", "ach_boosted"))
    assert (depleted["validity_effect"] > control["validity_effect"] + 1.5).all()
    assert (boosted["validity_effect"] < control["validity_effect"] - 0.5).all()


def test_ach_and_ne_depletion_move_the_switches_in_opposite_directions(per_run):
    control, ach, ne = (per_run.loc[c] for c in ("control", "ach_depleted", "ne_depleted"))
    assert (ach["switches"] > 3 * control["switches"]).all()  # invalid trials taken for changes
    assert (ach["false_switches"] > 3 * control["false_switches"]).all()
    assert (ne["switches"] < 0.5 * control["switches"]).all()
    assert (ne["trials_to_adopt"] > 2 * control["trials_to_adopt"]).all()  # slow to follow a change
    assert ach["trials_to_adopt"].mean() < control["trials_to_adopt"].mean()


def test_each_depletion_impairs_the_prediction_and_together_they_partly_cancel(per_run):
    control, ach, ne, both = (per_run.loc[c] for c in ("control", "ach_depleted", "ne_depleted", "ach_ne_depleted"))
    assert (ach["prediction_score"] < control["prediction_score"] - 0.03).all()
    assert (ne["prediction_score"] < control["prediction_score"] - 0.03).all()
    # NE depletion restores part of the switching lost to ACh depletion's low threshold, and ACh
    # depletion gives back the adaptation NE depletion took away
    assert (ne["switches"] < both["switches"]).all() and (both["switches"] < 0.7 * ach["switches"]).all()
    assert (both["trials_to_adopt"] < ne["trials_to_adopt"] / 3).all()


def test_ne_rises_after_an_unsignalled_change_and_the_observer_switches_to_the_new_cue():
    ep = with_blocks(_episodes(600, "world.validities=[0.9]", "world.block_trials=300", runs=5,
                               conditions=["control"]))
    for _, run in ep.groupby("run"):
        before = run[(run["episode"] >= 200) & (run["episode"] < 300)]
        after = run[(run["episode"] >= 300) & (run["episode"] < 320)]
        assert before["on_cue"].all()  # settled on the relevant cue before the change
        # NE jumps to the threshold 0.1 / 0.6 and beyond (a switch resets it), from a low mean
        assert before["ne"].mean() < 0.06 and after["ne"].max() > max(0.3, 5 * before["ne"].mean())
        assert after["switched"].astype(bool).any()
        adopted = run[(run["episode"] >= 300) & run["on_cue"]]["episode"].min() - 300
        assert adopted < 50
