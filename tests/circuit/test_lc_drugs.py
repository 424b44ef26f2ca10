"""NE drives behaviour in every LC model: a drug on the released NE level reaches the decision, the
level is the optional output ``ne`` that another region can read, and clamping NE high vs low changes
the dwell time (paired over 10 runs)."""

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.dwell import visits
from neurocur.analysis.stats.significance import wilcoxon_signed_rank
from neurocur.circuit import Circuit
from neurocur.regions import REGIONS, Probe, Region, Signal

#: the shipped circuit of each LC model
LC_CIRCUITS = {"lc.epsilon_greedy": "cd_misfa", "lc.softmax": "lc_softmax", "lc.adaptive_gain": "lc_adaptive_gain",
               "lc.fhn": "lc_fhn"}
#: each model's released level and a low and a high clamp of it: P(disengage) for the epsilon-greedy
#: rule, the gain of the softmax decision (1 / DA units) for the others
LEVELS = {"lc.epsilon_greedy": ("ne_tonic", 0.1, 0.9), "lc.softmax": ("ne_gain", 0.0, 30.0),
          "lc.adaptive_gain": ("ne_gain", 0.0, 30.0), "lc.fhn": ("ne_gain", 0.0, 30.0)}


def test_every_lc_model_is_covered():
    assert sorted(n for n in REGIONS.names() if n.startswith("lc.")) == sorted(LC_CIRCUITS)


def _run(circuit, world, seed, frames=4000):
    episodes = circuit.build(world, seed=seed).run(frames).episodes()
    return episodes.assign(condition="c", run=seed)


@pytest.mark.parametrize("type_name", LC_CIRCUITS)
def test_a_clamp_sets_the_level_the_decision_reads(type_name, circuits_dir, small, make_world):
    column, _, high = LEVELS[type_name]
    level = 0.7 if type_name == "lc.epsilon_greedy" else 2.0
    circuit = Circuit.from_toml(circuits_dir / f"{LC_CIRCUITS[type_name]}.toml", overrides=small)
    episodes = _run(circuit.lesion("LC", "clamp", level=level), make_world(), 3, frames=8000)
    np.testing.assert_array_equal(episodes[column], level)
    if type_name == "lc.epsilon_greedy":
        p = np.full(len(episodes), level)
    else:  # the softmax of the recorded Q at the clamped gain
        p = 1.0 / (1.0 + np.exp(-level * (episodes["q_disengage"] - episodes["q_engage"]).to_numpy()))
    observed = (episodes["action"] == "disengage").to_numpy()
    assert abs(observed.sum() - p.sum()) < 4 * np.sqrt((p * (1 - p)).sum())


def _paired_runs(type_name, level, circuits_dir, small, make_world, runs=10):
    circuit = Circuit.from_toml(circuits_dir / f"{LC_CIRCUITS[type_name]}.toml", overrides=small)
    drugged = circuit.lesion("LC", "clamp", level=level)
    return pd.concat([_run(drugged, make_world(), seed, frames=2000) for seed in range(runs)], ignore_index=True)


def test_clamping_tonic_ne_high_vs_low_changes_the_dwell_time(circuits_dir, small, make_world):
    """The paper's LC: P(disengage) clamped at 0.9 vs 0.1, 10 runs paired by seed."""
    dwell = {level: visits(_paired_runs("lc.epsilon_greedy", level, circuits_dir, small, make_world))
             .groupby("run")["n_episodes"].mean() for level in (0.1, 0.9)}
    test = wilcoxon_signed_rank(dwell[0.1], dwell[0.9])
    assert test["p_value"] < 0.01 and test["effect_size"] == 1.0  # longer visits on every run
    assert dwell[0.1].mean() > 5 * dwell[0.9].mean()


@pytest.mark.parametrize("type_name", [t for t, (column, _, _) in LEVELS.items() if column == "ne_gain"])
def test_clamping_the_gain_high_vs_low_makes_decisions_follow_q(type_name, circuits_dir, small, make_world):
    """The gain models: the share of decisions that take the better action (by the recorded Q), with the
    gain clamped at 30 vs 0 (1 / DA units), 10 runs paired by seed."""
    share = {}
    for level in (0.0, 30.0):
        episodes = _paired_runs(type_name, level, circuits_dir, small, make_world)
        better = np.where(episodes["q_disengage"] > episodes["q_engage"], "disengage", "engage")
        decided = episodes["q_disengage"] != episodes["q_engage"]
        share[level] = (episodes["action"] == better)[decided].groupby(episodes["run"][decided]).mean()
    test = wilcoxon_signed_rank(share[30.0], share[0.0])
    assert test["p_value"] < 0.01 and test["effect_size"] == 1.0
    assert share[30.0].min() > 0.9 and abs(share[0.0].mean() - 0.5) < 0.1


@REGIONS.register("test.ne_reader")
class NEReader(Region):
    """Reads the LC's released NE and records it."""

    inputs = (Signal("ne", "float64", ()),)
    probes = (Probe("ne_read", "float", "LC units"),)

    def step(self, ne):
        self.ne = ne
        return ()

    def record(self):
        return (self.ne,)


@pytest.mark.parametrize("type_name", LC_CIRCUITS)
def test_another_region_reads_the_released_ne_when_wired(type_name, tmp_path, small, make_world):
    column = LEVELS[type_name][0]
    path = tmp_path / "reader.toml"
    path.write_text(f'extends = "{LC_CIRCUITS[type_name]}"\n[regions.reader]\ntype = "test.ne_reader"\n'
                    '[[edges]]\nfrom = "LC"\nsignal = "ne"\nto = "reader"\n')
    for circuit in (Circuit.from_toml(path, overrides=small),
                    Circuit.from_toml(path, overrides=small).lesion("LC", "noise", sd=0.05)):
        episodes = _run(circuit, make_world(), 1, frames=2000)
        np.testing.assert_array_equal(episodes["ne_read"], episodes[column])


@pytest.mark.parametrize("type_name", ["lc.softmax", "lc.adaptive_gain", "lc.fhn"])
def test_a_released_gain_is_never_negative(type_name, circuits_dir, small, make_world):
    """A drug that would release a negative gain releases 0: the recorded gain is 0 and the decision is a
    fair coin (a negative gain would reverse the preference the Q values give)."""
    circuit = Circuit.from_toml(circuits_dir / f"{LC_CIRCUITS[type_name]}.toml", overrides=small)
    episodes = _run(circuit.lesion("LC", "clamp", level=-5.0), make_world(), 3, frames=8000)
    np.testing.assert_array_equal(episodes["ne_gain"], 0.0)
    n, leave = len(episodes), int((episodes["action"] == "disengage").sum())
    assert abs(leave - n / 2) < 4 * np.sqrt(n / 4)
