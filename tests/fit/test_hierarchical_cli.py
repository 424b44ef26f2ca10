"""`neurocur fit --hierarchical` and `neurocur compare --hierarchical` on a bandit trial table simulated here with
plain numpy from known group parameters: the files against the library called on the same replays, each
subject's MAP against an independent numpy/scipy maximum of log L + log prior under group.csv's prior, the
comparison's BMS against bms() on its own table, the generating model picked by iBIC, and the refusals."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from scipy import optimize, special

from neurocur.cli import main
from neurocur.fit.bms import bms
from neurocur.fit.hierarchical import fit_hierarchical
from neurocur.fit.models import load_fit_data
from neurocur.fit.study import condition_of, default_bounds, make_replays

P_REWARD = (0.7, 0.3)
SUBJECTS, TRIALS = 12, 60
#: the EM's cap, starts and the sampled evidence's draws in these tests (small: the machine is shared; each draw
#: costs a replay of every subject at its learning rate)
E_STEPS, STARTS, SEED, SAMPLES = 4, 2, 3, 200
BOUNDS = {"PFC.alpha": (0.0, 1.0), "LC.beta": (0.0, 50.0)}


def loglik(choices, outcomes, alpha, beta):
    """log P of the choices under the delta rule (Q0 = 0) and a softmax; plain numpy."""
    q, total = np.zeros(2), 0.0
    for c, r in zip(choices, outcomes):
        z = beta * q
        total += z[c] - z.max() - np.log(np.exp(z - z.max()).sum())
        q[c] += alpha * (r - q[c])
    return total


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    """12 subjects x 60 trials: logit alpha ~ N(logit 0.3, 0.6^2), logit(beta / 50) ~ N(logit 0.08, 0.4^2);
    written with the column subjID and 1-based choices."""
    rng = np.random.default_rng(2011)
    rows, truth = [], {}
    for s in range(SUBJECTS):
        alpha = special.expit(rng.normal(special.logit(0.3), 0.6))
        beta = 50 * special.expit(rng.normal(special.logit(0.08), 0.4))
        q, choices, outcomes = np.zeros(2), [], []
        for _ in range(TRIALS):
            p = np.exp(beta * q - (beta * q).max())
            c = int(rng.choice(2, p=p / p.sum()))
            r = float(rng.random() < P_REWARD[c])
            q[c] += alpha * (r - q[c])
            choices.append(c)
            outcomes.append(r)
        truth[f"p{s:02d}"] = (np.array(choices), np.array(outcomes))
        rows.append(pd.DataFrame({"subjID": f"p{s:02d}", "trial": np.arange(1, TRIALS + 1),
                                  "choice": np.array(choices) + 1, "outcome": outcomes}))
    path = tmp_path_factory.mktemp("hier") / "choices.csv"
    pd.concat(rows).to_csv(path, index=False)
    return path, truth


OPTIONS = ["--columns", "subject=subjID", "--one-based", "--em-iterations", str(E_STEPS), "--starts", str(STARTS),
           "--seed", str(SEED), "--evidence-samples", str(SAMPLES)]


@pytest.fixture(scope="module")
def fitted(table, tmp_path_factory):
    path, _ = table
    out = tmp_path_factory.mktemp("hier") / "fit"
    # two worker processes here, one in the library's fit below: the same numbers (the tests that follow)
    status = main(["fit", str(path), "--experiment", "bandit", "--hierarchical", *OPTIONS, "--jobs", "2",
                   "--out", str(out)])
    assert status == 0
    experiment, condition = condition_of("bandit", "delta")
    data = load_fit_data(path, condition, columns=["subject=subjID"], one_based=True)
    replays = make_replays(experiment, condition, data, list(BOUNDS))
    library = fit_hierarchical(replays, default_bounds(condition, list(BOUNDS), {}), names=[d.name for d in data],
                               seed=SEED, starts=STARTS, max_iter=E_STEPS, n_samples=SAMPLES)
    return out, library


def test_fit_hierarchical_writes_the_library_fit(fitted):
    out, library = fitted
    group = pd.read_csv(out / "group.csv")
    assert list(group.columns[:5]) == ["param", "mean", "sd", "ci_low", "ci_high"]
    assert list(group["param"]) == list(BOUNDS)
    columns = ["mean", "sd", "ci_low", "ci_high", "mu", "sigma", "mu_se"]
    np.testing.assert_allclose(group[columns].to_numpy(), library.group[columns].to_numpy(), rtol=1e-8, atol=1e-10)
    subjects = pd.read_csv(out / "fit.csv")
    assert list(subjects.columns) == ["dataset", "param", "estimate", "ci_low", "ci_high"]
    assert "pooled" not in set(subjects["dataset"]) and subjects["dataset"].nunique() == SUBJECTS
    assert list(subjects["dataset"] + subjects["param"]) == list(library.subjects["dataset"] + library.subjects["param"])
    np.testing.assert_allclose(subjects[["estimate", "ci_low", "ci_high"]].to_numpy(),
                               library.subjects[["estimate", "ci_low", "ci_high"]].to_numpy(), rtol=1e-8, atol=1e-10)
    summary = json.loads((out / "summary.json").read_text())
    for key in ("ibic", "ibic_laplace", "log_evidence", "log_evidence_laplace"):
        assert summary[key] == pytest.approx(getattr(library, key), rel=1e-10)
    assert summary["n_obs"] == SUBJECTS * TRIALS and summary["iterations"] == E_STEPS
    # 4 E-steps from the wide first prior do not reach the stopping rule: flagged and warned
    assert summary["converged"] is False and library.converged is False
    assert any("did not converge within 4 E-steps" in w for w in summary["warnings"])


def test_the_written_fit_is_the_same_for_any_number_of_jobs(fitted, table, tmp_path):
    """--jobs 1 (the E-steps in this process) writes byte for byte the tables and the summary's numbers that
    --jobs 2 wrote."""
    out, _ = fitted
    path, _ = table
    one = tmp_path / "one"
    assert main(["fit", str(path), "--experiment", "bandit", "--hierarchical", *OPTIONS, "--jobs", "1",
                 "--out", str(one)]) == 0
    for name in ("fit.csv", "group.csv"):
        assert (one / name).read_bytes() == (out / name).read_bytes(), name
    summaries = [json.loads((folder / "summary.json").read_text()) for folder in (one, out)]
    for key in ("ibic", "ibic_laplace", "log_evidence", "log_evidence_mcse", "log_evidence_laplace", "iterations"):
        assert summaries[0][key] == summaries[1][key], key


def test_each_subjects_estimate_is_the_map_under_the_written_group_prior(fitted, table):
    """An independent MAP: numpy's log-likelihood plus the normal prior of group.csv's mu, sigma on the logit
    scales, maximised by scipy from the truth's neighbourhood; the CLI's estimates agree to 1e-3 on the logit
    scale (a MAP under a prior 10 % narrower or with mu off by 0.1 moves them by more)."""
    out, _ = fitted
    _, truth = table
    group = pd.read_csv(out / "group.csv").set_index("param")
    mu, sigma = group.loc[list(BOUNDS), "mu"].to_numpy(), group.loc[list(BOUNDS), "sigma"].to_numpy()
    subjects = pd.read_csv(out / "fit.csv")
    for name in ("p00", "p05", "p11"):
        choices, outcomes = truth[name]

        def cost(x, choices=choices, outcomes=outcomes):
            return -loglik(choices, outcomes, special.expit(x[0]), 50 * special.expit(x[1])) + 0.5 * np.sum(
                ((x - mu) / sigma) ** 2)

        best = min((optimize.minimize(cost, start, method="Nelder-Mead",
                                      options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 4000})
                    for start in (mu, mu + 1.0, mu - 1.0)), key=lambda r: r.fun)
        mine = subjects[subjects["dataset"] == name].set_index("param")["estimate"]
        written = np.array([special.logit(mine["PFC.alpha"]), special.logit(mine["LC.beta"] / 50)])
        np.testing.assert_allclose(written, best.x, atol=1e-3)


def test_compare_hierarchical_picks_the_generating_model(table, fitted, tmp_path):
    path, truth = table
    out = tmp_path / "compare"
    status = main(["compare", str(path), "--experiment", "bandit", "--models", "delta", "delta_posneg",
                   "delta_perseveration_lapse", "--hierarchical", *OPTIONS, "--out", str(out)])
    assert status == 0
    ranked = pd.read_csv(out / "hierarchical.csv")
    assert list(ranked.columns[:4]) == ["model", "ibic", "laplace_ibic", "log_evidence"]
    assert ranked.loc[ranked["ibic"].idxmin(), "model"] == "delta"
    assert ranked.loc[ranked["laplace_ibic"].idxmin(), "model"] == "delta"
    table_ = pd.read_csv(out / "compare.csv")
    assert len(table_) == 3 * SUBJECTS
    # each model's subjects' Laplace log evidences add up to its Laplace evidence
    sums = table_.groupby("model")["log_evidence"].sum()
    for _, row in ranked.iterrows():
        assert sums[row["model"]] == pytest.approx(row["log_evidence_laplace"], abs=1e-8)
    # delta's fit is fit --hierarchical's (same seed, starts, E-steps): its log-likelihood at each MAP is numpy's
    # at fit.csv's estimate
    delta = table_[table_["model"] == "delta"].set_index("dataset")
    estimates = pd.read_csv(fitted[0] / "fit.csv").pivot(index="dataset", columns="param", values="estimate")
    for name, (choices, outcomes) in truth.items():
        assert delta.loc[name, "loglik"] == pytest.approx(
            loglik(choices, outcomes, estimates.loc[name, "PFC.alpha"], estimates.loc[name, "LC.beta"]), abs=1e-8)
    # BMS on the per-subject Laplace log evidences, in the table's model order
    wide = table_.pivot(index="dataset", columns="model", values="log_evidence")[
        ["delta", "delta_posneg", "delta_perseveration_lapse"]]
    expected = bms(wide.to_numpy())
    selection = pd.read_csv(out / "bms.csv")
    np.testing.assert_allclose(selection["pxp"], expected.pxp, atol=1e-12)
    np.testing.assert_allclose(selection["expected"], expected.expected, atol=1e-12)
    assert list(selection["model"]) == ["delta", "delta_posneg", "delta_perseveration_lapse"]
    assert (delta["n_obs"] == TRIALS).all() and (delta["n_params"] == 2).all()


@pytest.mark.parametrize("argv, message", [
    (["fit", "--hierarchical", "--ci", "bootstrap"], "--hierarchical: key '--ci': expected profile"),
    (["fit", "--em-iterations", "3"], "--em-iterations: expected --hierarchical"),
    (["fit", "--jobs", "2"], "--jobs: expected --hierarchical"),
    (["compare", "--models", "delta", "--evidence-samples", "30"], "--evidence-samples: expected --hierarchical"),
    (["compare", "--models", "delta", "delta_posneg", "--hierarchical", "--no-loo"], "key '--no-loo'"),
])
def test_refusals(table, tmp_path, capsys, argv, message):
    path, _ = table
    out = tmp_path / "out"
    status = main([argv[0], str(path), "--experiment", "bandit", "--columns", "subject=subjID", "--one-based",
                   *argv[1:], "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and message in err[0]
    assert not out.exists()


@pytest.mark.parametrize("command", ["fit", "compare"])
def test_one_data_set_is_refused(table, tmp_path, capsys, command):
    path, _ = table
    one = tmp_path / "one.csv"
    pd.read_csv(path).query("subjID == 'p00'").to_csv(one, index=False)
    out = tmp_path / "out"
    models = ["--models", "delta", "delta_posneg"] if command == "compare" else []
    status = main([command, str(one), "--experiment", "bandit", "--columns", "subject=subjID", "--one-based",
                   "--hierarchical", *models, "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "expected at least 2 data sets for --hierarchical" in err[0]
    assert not out.exists()
