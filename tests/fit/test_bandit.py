"""Fitting people's bandit choices: `neurocur fit TABLE --experiment bandit` against an independent plain-numpy
maximum likelihood (delta rule + softmax, scipy over the same bounds); each model's likelihood against the numpy
one; a missed trial skipped; a simulated agent's trials replayed exactly."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from scipy import optimize

from neurocur.cli import main
from neurocur.experiments import load_experiment, run_experiment
from neurocur.fit.bootstrap import parametric_bootstrap
from neurocur.fit.study import make_replays, simulate
from neurocur.fit.trials import read_trials, trials_from_table
from neurocur.results import ResultsStore

P_REWARD = (0.7, 0.3)


def numpy_loglik(choices, outcomes, *, alpha=0.3, beta=3.0, q0=0.0, kappa=0.0, lapse=0.0, alpha_neg=None, k=2):
    """log P of the choices: Q = q0, softmax(beta Q + kappa [repeat]) mixed with a uniform lapse, then the delta
    rule (alpha, or alpha / alpha_neg by the sign of the error); a choice < 0 is a missed trial, skipped."""
    q, previous, total = np.full(k, float(q0)), -1, 0.0
    for c, r in zip(choices, outcomes):
        if c < 0:
            continue
        z = beta * q + kappa * (np.arange(k) == previous)
        p = np.exp(z - z.max())
        p = (1 - lapse) * p / p.sum() + lapse / k
        total += np.log(p[c])
        delta = r - q[c]
        q[c] += (alpha if alpha_neg is None or delta > 0 else alpha_neg) * delta
        previous = c
    return total


def simulate_subject(rng, n, *, alpha, beta, k=2):
    q, choices, outcomes = np.zeros(k), [], []
    for _ in range(n):
        p = np.exp(beta * q - (beta * q).max())
        c = int(rng.choice(k, p=p / p.sum()))
        r = float(rng.random() < P_REWARD[c])
        q[c] += alpha * (r - q[c])
        choices.append(c)
        outcomes.append(r)
    return np.array(choices), np.array(outcomes)


def numpy_mle(choices, outcomes, bounds):
    """An independent fit: L-BFGS-B from a grid of starts, polished with tight tolerances."""
    def cost(x):
        return -numpy_loglik(choices, outcomes, alpha=x[0], beta=x[1])
    starts = [(a, b) for a in (0.1, 0.5, 0.9) for b in (1.0, 5.0, 20.0)]
    best = min((optimize.minimize(cost, s, method="L-BFGS-B", bounds=bounds,
                                  options={"ftol": 1e-15, "gtol": 1e-10}) for s in starts), key=lambda r: r.fun)
    return best.x, -best.fun


@pytest.fixture(scope="module")
def subjects():
    rng = np.random.default_rng(2011)
    return {f"s{i}": simulate_subject(rng, 100, alpha=a, beta=b) for i, (a, b) in enumerate(((0.2, 4.0), (0.5, 2.5),
                                                                                              (0.35, 6.0)))}


def test_fit_a_one_based_tab_separated_table_without_fit_or_bounds(tmp_path, subjects):
    rows = [pd.DataFrame({"subjID": name, "trial": np.arange(1, 101), "choice": c + 1, "outcome": r})
            for name, (c, r) in subjects.items()]
    data = tmp_path / "choices.txt"
    pd.concat(rows).to_csv(data, sep="\t", index=False)
    out = tmp_path / "fit"
    status = main(["fit", str(data), "--experiment", "bandit", "--columns", "subject=subjID", "--one-based",
                   "--out", str(out)])
    assert status == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["fitted"] == ["PFC.alpha", "LC.beta"]  # the condition's declared free parameters
    assert summary["bounds"] == {"PFC.alpha": [0.0, 1.0], "LC.beta": [0.0, 50.0]}  # their declared domains
    assert summary["one_based"] is True and summary["skipped"] == 0 and summary["n_obs"] == 300
    fit = pd.read_csv(out / "fit.csv")
    fits = {f["dataset"]: f for f in summary["fits"]}
    for name, (c, r) in subjects.items():
        x, loglik = numpy_mle(c, r, [(0.0, 1.0), (0.0, 50.0)])
        est = fit[fit["dataset"] == name].set_index("param")["estimate"]
        assert abs(est["PFC.alpha"] - x[0]) < 1e-4 and abs(est["LC.beta"] - x[1]) < 1e-4, (name, est, x)
        assert abs(fits[name]["loglik"] - loglik) < 1e-6, name


def _table(choices, outcomes, name="s"):
    return pd.DataFrame({"subject": name, "trial": np.arange(len(choices)),
                         "choice": [None if c < 0 else int(c) for c in choices], "outcome": outcomes})


def _replay(condition_name, table, fitted):
    experiment = load_experiment("bandit")
    condition = experiment.conditions[condition_name]
    data = trials_from_table(table, condition.make_world().context_names)
    return make_replays(experiment, condition, data, fitted)[0], data[0]


def test_a_missed_trial_is_skipped_and_counted(tmp_path, subjects):
    c, r = subjects["s0"]
    c = c.copy()
    c[[0, 10, 11, 57]] = -1  # missed: the first trial, two in a row, one later
    replay, trials = _replay("delta", _table(c, r), ["PFC.alpha", "LC.beta"])
    assert trials.skipped == 4 and replay.n_obs == 96
    for theta in ({"PFC.alpha": 0.2, "LC.beta": 4.0}, {"PFC.alpha": 0.8, "LC.beta": 1.5}):
        expected = numpy_loglik(c, r, alpha=theta["PFC.alpha"], beta=theta["LC.beta"])
        assert abs(replay.loglik(theta) - expected) < 1e-9
        assert abs(replay.episode_logp(theta).sum() - expected) < 1e-9
    # a plausible wrong reading, a missed trial taken as option 0 (scored and learned from), differs
    as_zero = numpy_loglik(np.where(c < 0, 0, c), r, alpha=0.2, beta=4.0)
    assert abs(replay.loglik({"PFC.alpha": 0.2, "LC.beta": 4.0}) - as_zero) > 1e-3
    data = tmp_path / "missed.csv"
    _table(c, r).to_csv(data, index=False)
    out = tmp_path / "fit"
    assert main(["fit", str(data), "--experiment", "bandit", "--out", str(out), "--ci", "profile"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["skipped"] == 4 and summary["skipped_by_subject"] == {"s": 4} and summary["n_obs"] == 96


@pytest.mark.parametrize("condition,theta,numpy_theta", [
    ("delta_posneg", {"PFC.alpha_pos": 0.6, "PFC.alpha_neg": 0.1, "LC.beta": 3.0},
     {"alpha": 0.6, "alpha_neg": 0.1, "beta": 3.0}),
    ("delta_posneg", {"PFC.alpha_pos": 0.05, "PFC.alpha_neg": 0.9, "LC.beta": 7.0},
     {"alpha": 0.05, "alpha_neg": 0.9, "beta": 7.0}),
    ("delta_perseveration_lapse", {"PFC.alpha": 0.3, "LC.beta": 4.0, "LC.kappa": 1.5, "LC.lapse": 0.0},
     {"alpha": 0.3, "beta": 4.0, "kappa": 1.5}),
    ("delta_perseveration_lapse", {"PFC.alpha": 0.3, "LC.beta": 4.0, "LC.kappa": -2.0, "LC.lapse": 0.2},
     {"alpha": 0.3, "beta": 4.0, "kappa": -2.0, "lapse": 0.2}),
    ("delta_perseveration_lapse", {"PFC.alpha": 0.7, "LC.beta": 30.0, "LC.kappa": 0.0, "LC.lapse": 0.1},
     {"alpha": 0.7, "beta": 30.0, "lapse": 0.1}),
])
def test_each_model_equals_the_numpy_likelihood(subjects, condition, theta, numpy_theta):
    c, r = subjects["s1"]
    c = c.copy()
    c[[5, 40]] = -1
    replay, _ = _replay(condition, _table(c, r), list(theta))
    expected = numpy_loglik(c, r, **numpy_theta)
    assert abs(replay.loglik(theta) - expected) < 1e-9  # vectorised across thetas
    assert abs(replay.episode_logp(theta).sum() - expected) < 1e-9  # stepped
    several = [theta, {**theta, "LC.beta": 0.5}]
    np.testing.assert_allclose(replay.loglik(several), [numpy_loglik(c, r, **numpy_theta),
                                                        numpy_loglik(c, r, **{**numpy_theta, "beta": 0.5})],
                               rtol=0, atol=1e-9)


def test_a_simulated_agent_replays_exactly(tmp_path):
    experiment = load_experiment("bandit", runs=2, steps=80)
    out = tmp_path / "bandit"
    run_experiment(experiment, out, conditions=["delta_perseveration_lapse"])
    condition = experiment.conditions["delta_perseveration_lapse"]
    data = read_trials(out, condition.make_world().context_names)
    assert [d.name for d in data] == ["delta_perseveration_lapse/0", "delta_perseveration_lapse/1"]
    replays = make_replays(experiment, condition, data, ["PFC.alpha", "LC.beta", "LC.kappa", "LC.lapse"])
    episodes, _ = ResultsStore(out).load()
    for i, replay in enumerate(replays):
        acted = np.log(episodes[episodes["run"] == i]["p_chosen"].to_numpy())
        assert len(replay.logp) == 80
        own = replay.episodes
        np.testing.assert_array_equal(own["next_context"], data[i].choices)
        np.testing.assert_allclose(replay.logp, acted, rtol=0, atol=1e-9)
        np.testing.assert_allclose(own["reward"], data[i].outcomes)
        theta = {"PFC.alpha": 0.3, "LC.beta": 3.0, "LC.kappa": 0.5, "LC.lapse": 0.05}  # the condition's own
        assert abs(replay.loglik(theta) - acted.sum()) < 1e-9


def test_compare_the_declared_models_on_a_trial_table(tmp_path, subjects):
    c, r = subjects["s2"]
    data = tmp_path / "choices.csv"
    _table(c, r, "s2").to_csv(data, index=False)
    out = tmp_path / "compare"
    assert main(["compare", str(data), "--experiment", "bandit", "--models", "delta", "delta_posneg", "--no-loo",
                 "--out", str(out), "--starts", "3"]) == 0
    table = pd.read_csv(out / "compare.csv").set_index("model")
    assert table.loc["delta", "n_params"] == 2 and table.loc["delta_posneg", "n_params"] == 3  # each its own keys
    assert table.loc["delta", "n_obs"] == 100
    _, loglik = numpy_mle(c, r, [(0.0, 1.0), (0.0, 50.0)])
    assert abs(table.loc["delta", "loglik"] - loglik) < 1e-6
    assert table.loc["delta_posneg", "loglik"] >= loglik - 1e-6  # a model that nests it fits at least as well


def test_parameter_recovery_and_the_bootstrap_simulate_trials(tmp_path):
    """`neurocur recover bandit` (no --fit: the declared parameters): each data set's estimate equals the numpy
    maximum likelihood of the same simulated trials (the recovery's seeds, redrawn here); the parametric bootstrap
    of a trial fit runs on trials too."""
    out = tmp_path / "rec"
    assert main(["recover", "bandit", "--datasets", "3", "--episodes", "120", "--starts", "3", "--out", str(out)]) == 0
    table = pd.read_csv(out / "recovery.csv")
    assert sorted(table["param"].unique()) == ["LC.beta", "PFC.alpha"]
    condition = load_experiment("bandit").conditions["delta"]
    root = np.random.SeedSequence(0)
    draw = np.random.default_rng(root.spawn(1)[0])
    bounds = [(0.0, 1.0), (0.0, 50.0)]
    for i, child in enumerate(root.spawn(3)):
        truth = dict(zip(("PFC.alpha", "LC.beta"), draw.uniform([0.0, 0.0], [1.0, 50.0])))
        trials, _ = simulate(condition, truth, child, 120, name=f"d{i}")
        rows = table[table["dataset"] == f"d{i}"].set_index("param")
        assert abs(rows.loc["PFC.alpha", "true"] - truth["PFC.alpha"]) < 1e-12
        x, loglik = numpy_mle(trials.choices, trials.outcomes, bounds)
        assert abs(rows.loc["LC.beta", "loglik"] - loglik) < 1e-6, i
        if loglik < -1e-3:  # not a data set a greedy choice explains perfectly (a flat likelihood at its bound)
            assert abs(rows.loc["PFC.alpha", "estimate"] - x[0]) < 1e-4 and abs(rows.loc["LC.beta", "estimate"] - x[1]) < 1e-4
    trials, _ = simulate(condition, {"PFC.alpha": 0.3, "LC.beta": 3.0}, np.random.SeedSequence(9), 80, name="b")
    boot = parametric_bootstrap(condition, {"PFC.alpha": 0.3, "LC.beta": 3.0}, len(trials),
                                {"PFC.alpha": (0.0, 1.0), "LC.beta": (0.0, 50.0)}, replicates=3, seed=[0, 0], starts=1,
                                dataset="b")
    assert len(boot.replicates) == 6 and set(boot.ci) == {"PFC.alpha", "LC.beta"}
