"""Parametric bootstrap intervals against a closed form: the free choice with a stay bonus and nothing to learn.

With the practice signal's rate and noise at 0 no task's error ever falls, so learning progress and
eq 14's values stay 0, and the softmax chooses the current task with p(g) = e^g / (e^g + 3) (stay bonus
1, four tasks) at every episode. A data set's stay count K is Binomial(n, p(g)), the maximum-likelihood
gain is g(K / n) with g(p) = log(3 p / (1 - p)), and a bootstrap replicate's refit is g(K* / n) with
K* ~ Binomial(n, p(g-hat)): its percentile interval is g of the binomial's quantiles over n.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.fit.bootstrap import parametric_bootstrap, percentile_interval
from neurocur.fit.mle import fit_ml
from neurocur.fit.recovery import parameter_recovery
from neurocur.fit.study import replay_of, simulate

BOUNDS = {"LC.gain": (0.0, 5.0)}


class StayTask:
    """The free-choice condition with nothing to learn and a stay bonus of 1 (module docstring)."""

    def __init__(self):
        condition = load_experiment("free_choice").conditions["learning_progress"]
        self.circuit = condition.circuit.with_params({"HPC.rate": 0.0, "HPC.noise": 0.0, "LC.stay": 1.0})
        self.make_world = condition.make_world


def gain_of(p):
    return np.log(3 * p / (1 - p))


def stays_of(gain, n):
    return n * np.exp(gain) / (np.exp(gain) + 3)


@pytest.fixture(scope="module")
def task():
    return StayTask()


@pytest.fixture(scope="module")
def fitted(task):
    """Data sets of 80 and 320 episodes at gain 1, their fits (with profile intervals) and stay counts."""
    out = {}
    for n in (80, 320):
        behaviour, _ = simulate(task, {"LC.gain": 1.0}, np.random.SeedSequence(3), n)
        fit = fit_ml(replay_of(task, behaviour, np.random.SeedSequence(3), list(BOUNDS)), BOUNDS, starts=1)
        out[n] = fit, int((behaviour.decisions == behaviour.contexts).sum())
    return out


@pytest.fixture(scope="module")
def boots(task, fitted):
    return {n: parametric_bootstrap(task, fit.estimate, n, BOUNDS, replicates=80, seed=1, starts=1)
            for n, (fit, _) in fitted.items()}


def test_the_replicates_are_closed_form_refits_of_binomial_stay_counts(fitted, boots):
    n = 320
    (fit, k), boot = fitted[n], boots[n]
    assert abs(fit.estimate["LC.gain"] - gain_of(k / n)) < 1e-5
    g = boot.replicates["estimate"].to_numpy()
    stays = stays_of(g, n)
    np.testing.assert_allclose(stays, np.round(stays), atol=1e-3)  # each refit is g(K*/n) for an integer K*
    p = k / n
    sd = np.sqrt(n * p * (1 - p))
    assert abs(stays.mean() - n * p) < 4 * sd / np.sqrt(len(stays))  # K* ~ Binomial(n, p-hat)
    assert 0.7 < stays.std() / sd < 1.4
    analytic = gain_of(stats.binom.ppf([0.025, 0.975], n, p) / n)
    np.testing.assert_allclose(boot.ci["LC.gain"], analytic, atol=0.1)  # the 2.5 % quantile of 80: s.e. ~0.035
    assert boot.ci["LC.gain"] == percentile_interval(g, 0.95)


def test_the_interval_holds_the_estimate_narrows_like_one_over_root_n_and_agrees_with_the_profile(fitted, boots):
    widths = {}
    for n, boot in boots.items():
        lo, hi = boot.ci["LC.gain"]
        assert lo < fitted[n][0].estimate["LC.gain"] < hi
        widths[n] = hi - lo
    assert 1.5 < widths[80] / widths[320] < 2.7  # sqrt(320 / 80) = 2
    sd = {n: b.replicates["estimate"].std() for n, b in boots.items()}
    assert 1.6 < sd[80] / sd[320] < 2.5
    # 320 decisions, the gain well inside its bounds: Wilks' profile interval is accurate, and both agree
    # to 20 % of the interval's width
    profile = np.array(fitted[320][0].ci["LC.gain"])
    np.testing.assert_allclose(boots[320].ci["LC.gain"], profile, atol=0.2 * widths[320])


def test_replicates_are_reproducible_by_seed_and_spawned_from_it(task):
    kw = dict(replicates=5, starts=1)
    a = parametric_bootstrap(task, {"LC.gain": 1.0}, 80, BOUNDS, seed=7, **kw)
    b = parametric_bootstrap(task, {"LC.gain": 1.0}, 80, BOUNDS, seed=7, **kw)
    c = parametric_bootstrap(task, {"LC.gain": 1.0}, 80, BOUNDS, seed=8, **kw)
    pd.testing.assert_frame_equal(a.replicates, b.replicates)
    assert not np.allclose(a.replicates["estimate"], c.replicates["estimate"])
    assert list(a.replicates.columns) == ["dataset", "replicate", "param", "estimate"] and len(a.replicates) == 5
    child = np.random.SeedSequence(7).spawn(5)[2]  # replicate 2 is the refit of child 2's data set
    behaviour, _ = simulate(task, {"LC.gain": 1.0}, child, 80)
    direct = fit_ml(replay_of(task, behaviour, child, list(BOUNDS)), BOUNDS, starts=1, seed=2, ci=None)
    assert a.replicates["estimate"][2] == direct.estimate["LC.gain"]


def test_recovery_with_bootstrap_intervals_and_a_bad_number_of_replicates(task):
    table = parameter_recovery(task, BOUNDS, n_datasets=2, n_episodes=60, seed=4, starts=1, intervals="bootstrap",
                               bootstrap=6)
    row = table.iloc[1]
    boot = parametric_bootstrap(task, {"LC.gain": row["estimate"]}, 60, BOUNDS, replicates=6, seed=[4, 1], starts=1)
    assert (row["ci_low"], row["ci_high"]) == boot.ci["LC.gain"]
    with pytest.raises(ConfigError, match="--bootstrap: expected a number of bootstrap replicates of at least 2"):
        parametric_bootstrap(task, {"LC.gain": 1.0}, 60, BOUNDS, replicates=0)
    with pytest.raises(ConfigError, match="--ci"):
        parameter_recovery(task, BOUNDS, n_datasets=1, n_episodes=10, intervals="wald")
