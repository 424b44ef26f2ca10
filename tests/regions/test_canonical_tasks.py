"""The signatures of the three canonical tasks on small runs of their shipped experiments
(docs/validation.md): Gilzenrat et al. 2002 (phasic against tonic LC), Schultz, Dayan &
Montague 1997 (TD dopamine in trial time) and Aston-Jones & Cohen 2005 (the adaptive-gain
mode against the utility); and the TD model over a complete serial compound against its
analytic fixed point."""

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.validation import blocks_per_run, conditioning_per_run, d_prime, vigilance_per_run
from neurocur.contexts.conditioning import ConditioningWorld
from neurocur.experiments import load_experiment
from neurocur.experiments.run import run_one
from neurocur.regions.vta_td import TDTrialVTA


def _episodes(name, steps, *sets, runs=1):
    exp = load_experiment(name, sets=list(sets))
    tables = [run_one(c, r, steps, np.random.SeedSequence(7, spawn_key=(r,))).episodes
              for c in exp.select(None) for r in range(runs)]
    return pd.concat(tables, ignore_index=True)


@pytest.fixture(scope="module")
def vigilance():
    return vigilance_per_run(_episodes("gilzenrat2002", 150 * 300)).set_index("condition")


def test_phasic_lc_bursts_to_targets_over_a_low_baseline(vigilance):
    """Gilzenrat et al. 2002's model: h(v) rests low and bursts to targets at C = 0.95; at C = 0.55 it rests
    higher and hardly bursts, to targets or distractors alike."""
    phasic, tonic = vigilance.loc["phasic"], vigilance.loc["tonic"]
    assert phasic["burst_ratio"] > 4 * tonic["burst_ratio"]
    assert phasic["baseline"] < 0.12 < 0.15 < tonic["baseline"]
    assert phasic["peak_target"] > phasic["peak_distractor"] + 0.5  # the phasic LC tells targets apart
    assert tonic["peak_target"] - tonic["peak_distractor"] < 0.1  # the tonic LC hardly does


def test_phasic_mode_detects_targets_better(vigilance):
    phasic, tonic = vigilance.loc["phasic"], vigilance.loc["tonic"]
    assert phasic["d_prime"] > tonic["d_prime"] + 0.3
    assert phasic["false_alarm_rate"] < tonic["false_alarm_rate"]


def test_d_prime_with_the_log_linear_correction():
    assert d_prime(50, 100, 50, 100) == pytest.approx(0.0, abs=1e-12)
    from scipy.stats import norm

    assert d_prime(9, 10, 1, 10) == pytest.approx(norm.ppf(9.5 / 11) - norm.ppf(1.5 / 11), rel=1e-12)
    assert np.isfinite(d_prime(10, 10, 0, 40))


@pytest.fixture(scope="module")
def conditioning():
    return conditioning_per_run(_episodes("schultz1997", 200 * 25, "world.omit_after=150")).iloc[0]


def test_dopamine_moves_from_the_reward_to_the_cue(conditioning):
    assert conditioning["r_cue_trial"] > 0.5 and conditioning["r_reward_trial"] < -0.3
    assert conditioning["reward_first"] == pytest.approx(1.0)  # the first reward is unpredicted
    assert conditioning["cue_first"] == 0.0 and conditioning["reward_last"] < 0.01


def test_an_omitted_reward_dips_below_baseline(conditioning):
    assert conditioning["omissions"] > 3
    assert conditioning["omission_dip"] < conditioning["baseline"] - 0.5


def test_td_csc_reaches_its_fixed_point():
    """Without omissions delta vanishes at every step once learned: the weight of the component
    i steps after the cue is r gamma^(delay - 1 - i) up to the reward and 0 after, and DA at the
    cue is r gamma^delay (the cue is unpredicted: nothing precedes it)."""
    world = ConditioningWorld(trial_length=12, cue=2, delay=5, reward=2.0)
    vta = TDTrialVTA("VTA", rate=0.5, discount=0.9)
    vta.bind(world)
    vta.reset(np.random.default_rng(0))
    episode, _ = world.reset(seed=0)
    for _ in range(400):
        vta.step(episode, episode.reward)
        episode = world.step(0)[0]
    expected = np.zeros(world.n_states)
    expected[:5] = 2.0 * 0.9 ** (4 - np.arange(5))
    np.testing.assert_allclose(vta.weights, expected, atol=1e-9)
    da, da_cue, da_reward, baseline, omitted = vta.record()
    assert da_cue == pytest.approx(2.0 * 0.9**5, abs=1e-9) and abs(da_reward) < 1e-9 and baseline == 0.0
    assert not omitted


def test_td_csc_first_trial_fires_at_the_reward_only():
    world = ConditioningWorld(trial_length=10, cue=2, delay=4, reward=1.5)
    vta = TDTrialVTA("VTA")
    vta.bind(world)
    vta.reset(np.random.default_rng(0))
    episode = world.reset(seed=0)[0]
    (total,) = vta.step(episode, episode.reward)
    assert total == 1.5 and vta.record()[1:3] == (0.0, 1.5)


@pytest.fixture(scope="module")
def blocks():
    episodes = _episodes("adaptive_gain_2005", 450 * 20, "world.block_visits=150")
    return blocks_per_run(episodes, 150).set_index(["condition", "block"])


def test_adaptive_gain_mode_follows_the_utility(blocks):
    b = blocks.loc["adaptive_gain"]
    assert b.loc[1, "reward"] < 0.5 < b.loc[0, "reward"] and b.loc[2, "reward"] > 0.5
    assert b.loc[1, "late_ne_tonic"] > b.loc[0, "late_ne_tonic"] + 0.3  # utility falls: tonic mode
    assert b.loc[1, "late_ne_tonic"] > b.loc[2, "late_ne_tonic"] + 0.3  # utility rises again: phasic mode
    assert b.loc[1, "ne_gain"] < 0.5 * b.loc[0, "ne_gain"]
    assert b.loc[1, "late_disengage"] > b.loc[0, "late_disengage"] + 0.2  # and the agent explores
    fixed = blocks.loc["fixed_gain"]
    assert np.allclose(fixed["ne_gain"], 5.25)
