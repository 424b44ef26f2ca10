"""The ten2021 experiment's choice models (docs/ten2021.md): an agent of each condition replays exactly; the
random baseline and perseveration against closed forms; `neurocur fit TABLE --experiment ten2021 --condition
pc_lp` against an independent plain-numpy maximum likelihood of the paper's model (signals rescaled per
participant over the scored trials, the forced phase and the first free choice not scored)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import optimize, special

from neurocur.cli import main
from neurocur.experiments import load_experiment
from neurocur.fit.replay import Replay
from neurocur.fit.study import simulate
from neurocur.fit.ten2021_utilities import activity_signals
from neurocur.fit.trials import trials_from_table

OPTIONS = ["1D", "I1D", "2D", "R"]
P_CORRECT = (0.90, 0.82, 0.66, 0.50)
#: a live agent cannot know its session's range (module docstring of neurocur.regions.ten2021)
RAW = {"PFC.rescale": False, "PFC.unscored": 0}


@pytest.fixture(scope="module")
def experiment():
    return load_experiment("ten2021")


@pytest.mark.parametrize("name", ["random", "perseveration", "pc", "lp", "pc_lp", "pc_lp_time", "persev_pc",
                                  "persev_lp", "persev_pc_lp", "persev_pc_time", "persev_pc_lp_time"])
def test_an_agent_of_each_condition_replays_exactly(experiment, name):
    condition = experiment.conditions[name]
    trials, episodes = simulate(condition, RAW, np.random.SeedSequence(5), 130, name="agent")
    circuit = condition.circuit.with_params(RAW, source="test")
    replay = Replay(circuit, condition.make_world(), trials.seed, trials, fitted=list(condition.fit))
    acted = np.log(episodes["p_chosen"].to_numpy())
    np.testing.assert_allclose(replay.logp, acted, rtol=0, atol=1e-9)
    assert (replay.logp[:60] == 0).all() and (replay.logp[60:] < 0).all()  # forced given, free chosen
    blocks = trials.choices[:60].reshape(4, 15)
    assert (blocks == blocks[:, :1]).all() and sorted(blocks[:, 0]) == [0, 1, 2, 3]
    own = {key: getattr(circuit.specs[key.split(".")[0]].params, key.split(".")[1]) for key in condition.fit}
    if own:
        assert abs(replay.loglik(own) - acted.sum()) < 1e-9
    if name == "random":
        assert acted.sum() == pytest.approx(70 * np.log(0.25), abs=1e-12)


def numpy_loglik(choices, outcomes, weights, *, kappa=0.0, forced=60, unscored=1, signals=None):
    """The paper's model in plain numpy: signals before each choice, each rescaled to [0, 1] over the scored
    trials (every activity), softmax of sum_i c_i x_i + kappa [repeat] over the choices after the forced phase and
    the first ``unscored`` free ones."""
    signals = activity_signals(choices, outcomes, 4) if signals is None else signals
    rows = np.arange(forced + unscored, len(choices))
    utility = np.zeros((len(rows), 4))
    for name, c in weights.items():
        x = signals[name][rows].astype(float)
        span = x.max() - x.min()
        utility += c * ((x - x.min()) / span if span > 0 else 0.0)
    utility += kappa * (np.arange(4) == choices[rows - 1][:, None])
    return special.log_softmax(utility, axis=1)[np.arange(len(rows)), choices[rows]].sum()


def numpy_mle(choices, outcomes, names):
    signals = activity_signals(choices, outcomes, 4)

    def cost(x):
        return -numpy_loglik(choices, outcomes, dict(zip(names, x)), signals=signals)
    starts = [(a, b) for a in (-10.0, 0.0, 10.0) for b in (-10.0, 0.0, 10.0)]
    best = min((optimize.minimize(cost, s, method="L-BFGS-B", bounds=[(-100, 100)] * len(names),
                                  options={"ftol": 1e-15, "gtol": 1e-10}) for s in starts), key=lambda r: r.fun)
    return best.x, -best.fun


def numpy_agent(rng, n_free, c_pc, c_lp):
    """A participant: the forced blocks in a random order, then a softmax of c_pc PC + c_lp LP (raw signals)."""
    order = rng.permutation(4)
    choices, outcomes = [], []
    for t in range(60 + n_free):
        if t < 60:
            k = int(order[t // 15])
        else:
            s = activity_signals(np.array(choices + [0]), np.array(outcomes + [0.0]), 4)
            z = c_pc * s["pc"][t] + c_lp * s["lp"][t]
            k = int(rng.choice(4, p=np.exp(special.log_softmax(z))))
        choices.append(k)
        outcomes.append(float(rng.random() < P_CORRECT[k]))
    return np.array(choices), np.array(outcomes)


def write_trials(folder, subjects) -> Path:
    """A trial table (``subject, trial, choice, outcome``; choices by option name) of ``subjects``
    (name -> (choices, outcomes)) written as ``folder/trials.csv``."""
    table = pd.concat([pd.DataFrame({"subject": name, "trial": np.arange(1, len(c) + 1),
                                     "choice": [OPTIONS[k] for k in c], "outcome": r})
                       for name, (c, r) in subjects.items()])
    table.to_csv(folder / "trials.csv", index=False)
    return folder / "trials.csv"


def test_fit_pc_lp_equals_the_numpy_maximum_likelihood(tmp_path):
    rng = np.random.default_rng(2021)
    subjects = {f"p{i}": numpy_agent(rng, 80, c_pc, c_lp) for i, (c_pc, c_lp) in enumerate(((-4.0, 3.0), (2.0, 5.0),
                                                                                           (-1.0, -2.0)))}
    data = write_trials(tmp_path, subjects)
    out = tmp_path / "fit"
    assert main(["fit", str(data), "--experiment", "ten2021", "--condition", "pc_lp", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["fitted"] == ["PFC.pc", "PFC.lp"]
    assert summary["bounds"] == {"PFC.pc": [-100.0, 100.0], "PFC.lp": [-100.0, 100.0]}
    fit = pd.read_csv(out / "fit.csv")
    fits = {f["dataset"]: f for f in summary["fits"]}
    for name, (c, r) in subjects.items():
        x, loglik = numpy_mle(c, r, ["pc", "lp"])
        assert np.all(np.abs(x) < 99), x  # an interior maximum
        est = fit[fit["dataset"] == name].set_index("param")["estimate"]
        assert abs(est["PFC.pc"] - x[0]) < 1e-4 and abs(est["PFC.lp"] - x[1]) < 1e-4, (name, est, x)
        assert abs(fits[name]["loglik"] - loglik) < 1e-6, name


def test_each_condition_equals_the_numpy_likelihood(experiment):
    c, r = numpy_agent(np.random.default_rng(4), 50, -2.0, 3.0)
    table = pd.DataFrame({"subject": "s", "trial": np.arange(len(c)), "choice": c, "outcome": r})
    (trials,) = trials_from_table(table, OPTIONS)
    cases = [("random", {}, {}, 0.0), ("perseveration", {"LC.kappa": 1.3}, {}, 1.3),
             ("pc", {"PFC.pc": -7.0}, {"pc": -7.0}, 0.0), ("lp", {"PFC.lp": 4.0}, {"lp": 4.0}, 0.0),
             ("pc_lp_time", {"PFC.pc": 2.0, "PFC.lp": -1.0, "PFC.plays": 3.0},
              {"pc": 2.0, "lp": -1.0, "plays": 3.0}, 0.0),
             ("persev_pc_lp", {"LC.kappa": 0.8, "PFC.pc": -4.0, "PFC.lp": 6.0}, {"pc": -4.0, "lp": 6.0}, 0.8)]
    for name, theta, weights, kappa in cases:
        condition = experiment.conditions[name]
        replay = Replay(condition.circuit, condition.make_world(), None, trials, fitted=list(condition.fit))
        expected = numpy_loglik(c, r, weights, kappa=kappa)
        got = replay.loglik(theta) if theta else replay.logp.sum()
        assert abs(got - expected) < 1e-9, name
        assert (replay.logp[:61] == 0).all()  # the forced phase and the first free choice are not scored
    assert numpy_loglik(c, r, {}) == pytest.approx(49 * np.log(0.25), abs=1e-12)


def test_bic_and_the_hierarchical_n_count_the_scored_choices_only(tmp_path):
    """The forced phase (60 trials) and the first free choice are given, not scored: a BIC's n and the iBIC's N
    are the scored choices (49 per subject here, of 110 rows), as the paper's 249 of 310."""
    rng = np.random.default_rng(7)
    subjects = {f"p{i}": numpy_agent(rng, 50, -2.0, 3.0) for i in range(3)}
    data = write_trials(tmp_path, subjects)
    out = tmp_path / "fit"
    assert main(["fit", str(data), "--experiment", "ten2021", "--condition", "pc", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for fit in summary["fits"]:
        n = 49 if fit["dataset"] != "pooled" else 3 * 49
        assert fit["n_obs"] == n, fit
        assert fit["bic"] == pytest.approx(fit["n_params"] * np.log(n) - 2 * fit["loglik"], abs=1e-9)
    hier = tmp_path / "hfit"
    assert main(["fit", str(data), "--experiment", "ten2021", "--condition", "pc", "--hierarchical",
                 "--evidence-samples", "20", "--em-iterations", "3", "--out", str(hier)]) == 0
    summary = json.loads((hier / "summary.json").read_text())
    assert summary["n_obs"] == 3 * 49
    assert summary["ibic"] == pytest.approx(-2 * summary["log_evidence"] + 2 * np.log(3 * 49), abs=1e-6)
