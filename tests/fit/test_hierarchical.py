"""Hierarchical fits (EM with Laplace) against closed forms, simulated groups, and model selection by iBIC."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import integrate, special, stats

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.fit.hierarchical import Subject, _group_table, fit_hierarchical
from neurocur.fit.mle import fit_ml
from neurocur.fit.study import make_replays, simulate
from neurocur.fit.transforms import Transforms

FREE = (-np.inf, np.inf)
SIGNAL = ("HPC", "error")


# ---------------------------------------------------------------------------------------------- Gaussian subjects

def gaussian_group(seed=1, n_subjects=12, s=1.0):
    """y_ij ~ N(theta_i, s^2), theta_i ~ N(0.5, 0.8^2), n_i from 3 to 29 observations."""
    rng = np.random.default_rng(seed)
    n = rng.integers(3, 30, n_subjects)
    theta = rng.normal(0.5, 0.8, n_subjects)
    return [rng.normal(t, s, k) for t, k in zip(theta, n)], n


def gaussian_loglik(y, s=1.0):
    return lambda points: stats.norm.logpdf(y[None, :], points[:, :1], s).sum(axis=1)


def em_fixed_point(ys, s=1.0):
    """The EM fixed point of the Gaussian model by plain iteration of its closed-form E- and M-steps."""
    n = np.array([len(y) for y in ys])
    ybar = np.array([y.mean() for y in ys])
    mu, var = 0.0, 9.0
    for _ in range(100_000):
        prec = n / s**2 + 1 / var
        m, v = (n * ybar / s**2 + mu / var) / prec, 1 / prec
        new_mu = m.mean()
        new_var = np.mean((m - new_mu) ** 2 + v)
        if abs(new_mu - mu) < 1e-14 and abs(new_var - var) < 1e-14:
            break
        mu, var = new_mu, new_var
    return mu, np.sqrt(var), m, v


def test_gaussian_subjects_reach_the_closed_form_em_fixed_point_and_evidence():
    ys, n = gaussian_group()
    fit = fit_hierarchical([gaussian_loglik(y) for y in ys], {"m": FREE}, n_obs=n, vectorised=True, tol=1e-12,
                           max_iter=1000)
    mu, sigma, m, v = em_fixed_point(ys)
    assert fit.converged and fit.group["kind"].tolist() == ["identity"]
    assert abs(fit.mu[0] - mu) < 1e-5 and abs(fit.sigma[0] - sigma) < 1e-5
    np.testing.assert_allclose(fit.subjects["estimate"], m, atol=1e-5)
    z = stats.norm.ppf(0.975)
    np.testing.assert_allclose(fit.subjects["ci_high"] - fit.subjects["estimate"], z * np.sqrt(v), rtol=1e-4)
    # the exact log marginal likelihood at the fitted group: y_i ~ N(mu 1, s^2 I + sigma^2 1 1')
    exact = sum(stats.multivariate_normal(np.full(len(y), fit.mu[0]), np.eye(len(y)) + fit.sigma[0] ** 2).logpdf(y)
                for y in ys)
    assert abs(fit.log_evidence_laplace - exact) < 1e-6
    assert abs(fit.log_evidence - exact) < 4 * fit.log_evidence_mcse and 0 < fit.log_evidence_mcse < 0.2
    assert fit.n_samples == 2000 and fit.n_obs == n.sum()
    assert abs(fit.ibic - (-2 * fit.log_evidence + 2 * np.log(n.sum()))) < 1e-9
    # se(mu): the inverse information of the exact marginal likelihood for mu, sum_i 1 / (sigma^2 + s^2 / n_i)
    se = 1 / np.sqrt(np.sum(1 / (fit.sigma[0] ** 2 + 1 / n)))
    assert abs(fit.mu_se[0] - se) < 1e-5 * se
    row = fit.group.iloc[0]
    np.testing.assert_allclose([row["mean"], row["sd"], row["ci_low"], row["ci_high"]],
                               [mu, sigma, mu - z * se, mu + z * se], atol=1e-5)
    assert fit.summary()["iterations"] == fit.iterations == len(fit.history) > 3


def stop_step(ys, tol_evidence, tol_move, s=1.0):
    """The E-steps plain EM makes on the Gaussian model before its stop rule holds, in closed form: over a plain
    step, the exact log marginal likelihood (the Laplace one, exact here) changes by less than ``tol_evidence``
    or neither mu nor sigma moves by more than ``tol_move``."""
    n = np.array([len(y) for y in ys])
    ybar = np.array([y.mean() for y in ys])

    def evidence(mu, var):
        return sum(stats.multivariate_normal(np.full(len(y), mu), s**2 * np.eye(len(y)) + var).logpdf(y) for y in ys)

    mu, var = 0.0, 9.0
    previous = evidence(mu, var)
    for steps in range(2, 10_000):
        prec = n / s**2 + 1 / var
        m, v = (n * ybar / s**2 + mu / var) / prec, 1 / prec
        new_mu, new_var = m.mean(), np.mean((m - m.mean()) ** 2 + v)
        current = evidence(new_mu, new_var)
        moved = max(abs(new_mu - mu), abs(np.sqrt(new_var) - np.sqrt(var)))
        if abs(current - previous) < tol_evidence or moved < tol_move:
            return steps
        mu, var, previous = new_mu, new_var, current
    raise AssertionError("no stop")


def test_the_stop_rule_scales_the_evidence_tolerance_with_the_subjects():
    """EM stops when the Laplace log evidence changes by less than tol per subject (the numerical MAPs' errors add
    over the subjects), or mu and sigma move by less than tol: the E-steps of a closed-form plain EM."""
    ys, n = gaussian_group(seed=5, n_subjects=60)
    fit = fit_hierarchical([gaussian_loglik(y) for y in ys], {"m": FREE}, n_obs=n, vectorised=True, accelerate=False)
    per_subject = stop_step(ys, 1e-3 * len(ys), 1e-3)
    assert fit.converged and fit.iterations == per_subject
    assert stop_step(ys, 1e-3, 1e-3) > per_subject  # an absolute tolerance would have gone on


def test_a_model_without_free_parameters_is_evaluated():
    ys, n = gaussian_group(n_subjects=4)
    fit = fit_hierarchical([lambda p, y=y: stats.norm.logpdf(y, 0.0, 1.0).sum() for y in ys], {}, n_obs=n)
    assert fit.log_evidence == fit.log_evidence_laplace == pytest.approx(sum(stats.norm.logpdf(y).sum() for y in ys))
    assert fit.ibic == pytest.approx(-2 * fit.log_evidence) and fit.n_params == 0 and fit.subjects.empty


# ---------------------------------------------------------------------------------------------- bandit subjects

P_REWARD = (0.2, 0.8)


def simulate_bandit(alpha_pos, alpha_neg, beta, n_trials, rng):
    """Choices and rewards of a delta-rule softmax learner on a 2-armed bandit."""
    q = np.zeros(2)
    choices, rewards = np.zeros(n_trials, dtype=int), np.zeros(n_trials)
    for t in range(n_trials):
        c = int(rng.random() < special.expit(beta * (q[1] - q[0])))
        r = float(rng.random() < P_REWARD[c])
        delta = r - q[c]
        q[c] += (alpha_pos if delta > 0 else alpha_neg) * delta
        choices[t], rewards[t] = c, r
    return choices, rewards


def bandit_loglik(choices, rewards, alpha_pos, alpha_neg, beta):
    """log P(choices) for m parameter sets at once (arrays of shape (m,))."""
    q = [np.zeros(len(beta)), np.zeros(len(beta))]
    diff = np.empty((len(choices), len(beta)))
    for t, (c, r) in enumerate(zip(choices, rewards)):
        diff[t] = q[1] - q[0]
        delta = r - q[c]
        q[c] = q[c] + np.where(delta > 0, alpha_pos, alpha_neg) * delta
    return special.log_expit(np.where(choices[:, None] == 1, 1.0, -1.0) * beta * diff).sum(axis=0)


#: the candidate models: name -> (bounds, parameter sets (m, k) -> (alpha_pos, alpha_neg, beta))
FIXED_ALPHA = 0.3
MODELS = {
    "random": ({}, None),
    "fixed_alpha": ({"beta": (0.0, 20.0)}, lambda p: (np.full(len(p), FIXED_ALPHA), np.full(len(p), FIXED_ALPHA),
                                                      p[:, 0])),
    "delta": ({"alpha": (0.0, 1.0), "beta": (0.0, 20.0)}, lambda p: (p[:, 0], p[:, 0], p[:, 1])),
    "dual": ({"alpha_pos": (0.0, 1.0), "alpha_neg": (0.0, 1.0), "beta": (0.0, 20.0)},
             lambda p: (p[:, 0], p[:, 1], p[:, 2])),
}


def subjects_of(model, data):
    bounds, params = MODELS[model]
    if params is None:
        return [Subject(lambda p, n=c.size: np.full(len(p), n * np.log(0.5)), len(c), [], vectorised=True)
                for c, _ in data]
    return [Subject(lambda p, c=c, r=r: bandit_loglik(c, r, *params(p)), len(c), list(bounds), vectorised=True)
            for c, r in data]


def delta_group(n_subjects, n_trials, seed):
    """Subjects of the delta rule: logit(alpha) ~ N(logit 0.3, 0.8^2), logit(beta / 20) ~ N(logit 0.25, 0.5^2)."""
    rng = np.random.default_rng(seed)
    x = np.column_stack([rng.normal(special.logit(0.3), 0.8, n_subjects),
                         rng.normal(special.logit(0.25), 0.5, n_subjects)])
    truth = np.column_stack([special.expit(x[:, 0]), 20 * special.expit(x[:, 1])])
    data = [simulate_bandit(a, a, b, n_trials, rng) for a, b in truth]
    return truth, data


TRUE_MU, TRUE_SD = np.array([special.logit(0.3), special.logit(0.25)]), np.array([0.8, 0.5])


def population_mean(j: int) -> float:
    """E[theta_j] of the generating group on the own scale (alpha, then beta = 20 expit), by quadrature."""
    scale = (1.0, 20.0)[j]
    return integrate.quad(lambda u: scale * special.expit(TRUE_MU[j] + TRUE_SD[j] * u) * stats.norm.pdf(u),
                          -12, 12)[0]


def test_the_group_means_are_recovered_within_their_intervals():
    _, data = delta_group(40, 150, seed=0)
    fit = fit_hierarchical(subjects_of("delta", data), MODELS["delta"][0], seed=0)
    assert fit.converged and list(fit.group["param"]) == ["alpha", "beta"]
    z = stats.norm.ppf(0.975)
    assert np.all(np.abs(fit.mu - TRUE_MU) < z * fit.mu_se), (fit.mu, fit.mu_se, TRUE_MU)
    for j, row in enumerate(fit.group.itertuples()):  # on the own scale, the population's mean
        assert row.ci_low < population_mean(j) < row.ci_high, (row, population_mean(j))
    # the interval is the Louis information's, wider than the subjects' spread alone (sigma / sqrt(N))
    assert np.all(fit.mu_se > fit.sigma / np.sqrt(40))


def test_the_group_prior_improves_the_estimates_of_short_subjects():
    truth, data = delta_group(60, 40, seed=0)
    bounds = MODELS["delta"][0]
    fit = fit_hierarchical(subjects_of("delta", data), bounds, seed=0)
    ml = [fit_ml(s, bounds, starts=3, ci=None) for s in subjects_of("delta", data)]
    by_ml = np.array([[f.estimate["alpha"], f.estimate["beta"]] for f in ml])
    by_map = fit.subjects.pivot(index="dataset", columns="param", values="estimate").loc[
        [f"s{i}" for i in range(len(data))], ["alpha", "beta"]].to_numpy()
    rmse = lambda est: np.sqrt(np.mean((est - truth) ** 2, axis=0))  # noqa: E731
    r = lambda est: [stats.pearsonr(est[:, j], truth[:, j])[0] for j in range(2)]  # noqa: E731
    message = (f"alpha, beta: RMSE with prior {rmse(by_map)}, without {rmse(by_ml)}; "
               f"r with prior {r(by_map)}, without {r(by_ml)}")
    assert np.all(rmse(by_map) < rmse(by_ml)), message
    sub = fit.subjects
    assert ((sub["ci_low"] <= sub["estimate"]) & (sub["estimate"] <= sub["ci_high"])).all()
    print(message)


def test_the_integrated_bic_picks_the_generating_model():
    _, data = delta_group(40, 100, seed=5)
    fits = {name: fit_hierarchical(subjects_of(name, data), MODELS[name][0], seed=1) for name in MODELS}
    ibic = {name: f.ibic for name, f in fits.items()}
    assert min(ibic, key=ibic.get) == "delta", ibic
    laplace = {name: f.ibic_laplace for name, f in fits.items()}
    assert min(laplace, key=laplace.get) == "delta", laplace
    # the nested dual-rate model fits at least as well but pays 2 log N for each of its extra mu and sigma
    assert fits["dual"].log_evidence > fits["delta"].log_evidence - 3.0
    print(ibic)


def em_residual(fit, bounds, level=0.95):
    """One plain M-step from the fit's subjects' table (each MAP and its Laplace variance, read back from its
    interval on the unbounded scale): how far it moves mu and sigma from the reported ones."""
    t = Transforms(bounds)
    wide = lambda column: fit.subjects.pivot(index="dataset", columns="param", values=column)[t.keys].to_numpy()  # noqa: E731
    maps = t.to_unbounded(wide("estimate"))
    var = ((t.to_unbounded(wide("ci_high")) - maps) / stats.norm.ppf(0.5 + level / 2)) ** 2
    mu = maps.mean(axis=0)
    sigma = np.sqrt(np.mean((maps - mu) ** 2 + var, axis=0))
    return max(np.max(np.abs(mu - fit.mu)), np.max(np.abs(sigma - fit.sigma)))


def test_the_accelerated_em_reaches_the_plain_em_fixed_point_in_fewer_e_steps():
    """SQUAREM changes EM's path, not its fixed point: both stop where one more plain M-step from the reported
    subjects' table leaves mu and sigma where they are, and agree there to the E-step's optimiser tolerance."""
    _, data = delta_group(10, 60, seed=0)
    bounds = MODELS["delta"][0]
    fast, plain = (fit_hierarchical(subjects_of("delta", data), bounds, tol=1e-10, max_iter=1000, n_samples=10,
                                    accelerate=a) for a in (True, False))
    assert fast.converged and plain.converged
    assert em_residual(fast, bounds) < 1e-6 and em_residual(plain, bounds) < 1e-6
    np.testing.assert_allclose(fast.mu, plain.mu, atol=2e-6)
    np.testing.assert_allclose(fast.sigma, plain.sigma, atol=2e-6)
    np.testing.assert_allclose(fast.subjects["estimate"], plain.subjects["estimate"], rtol=1e-5)
    assert fast.iterations < 0.6 * plain.iterations, (fast.iterations, plain.iterations)


def test_a_seed_gives_the_same_fit_for_any_number_of_workers():
    _, data = delta_group(7, 40, seed=3)
    bounds = MODELS["delta"][0]
    one, *more = (fit_hierarchical(subjects_of("delta", data), bounds, seed=2, max_iter=8, n_samples=50, workers=w)
                  for w in (1, 2, 3))
    for fit in more:
        assert fit.history == one.history and fit.log_evidence == one.log_evidence
        assert np.array_equal(fit.mu, one.mu) and np.array_equal(fit.sigma, one.sigma)
        pd.testing.assert_frame_equal(fit.subjects, one.subjects, check_exact=True)
    # a subject's refusal in a worker reaches the caller as the same one line
    bad = subjects_of("delta", data)[:3] + [Subject(lambda p: np.full(len(p), np.nan), 40, list(bounds), vectorised=True)]
    with pytest.raises(ConfigError, match=r"^s3: key 'loglik': expected a log-likelihood that is finite or -inf"):
        fit_hierarchical(bad, bounds, workers=2)
    with pytest.raises(ConfigError, match="key 'workers': expected a number of worker processes >= 1"):
        fit_hierarchical(subjects_of("delta", data), bounds, workers=0)


def test_replays_are_subjects_as_for_fit_ml():
    """On free choices replayed through the learning-progress circuit (signal replay, as ``neurocur fit``):
    at each MAP the replay's own log-likelihood's slope in x = logit(gain / 60) balances the prior's,
    and the interval is the Laplace one of the replay's own curvature."""
    exp = load_experiment("free_choice")
    condition = exp.conditions["learning_progress"]
    data = [simulate(condition, {}, exp.run_seed(i), 60, signal=SIGNAL, name=f"d{i}")[0] for i in range(3)]
    replays = make_replays(exp, condition, data, ["LC.gain"], signal=SIGNAL)
    fit = fit_hierarchical(replays, {"LC.gain": (0.0, 60.0)}, names=[b.name for b in data], n_samples=200)
    assert list(fit.subjects["dataset"]) == ["d0", "d1", "d2"] and fit.n_obs == 180
    h = 1e-3
    for replay, row in zip(replays, fit.subjects.itertuples()):
        x = special.logit(row.estimate / 60)
        ll = [replay.loglik({"LC.gain": 60 * special.expit(x + d)}) for d in (-h, 0.0, h)]
        slope, curvature = (ll[2] - ll[0]) / (2 * h), (ll[2] - 2 * ll[1] + ll[0]) / h**2
        assert abs(slope - (x - fit.mu[0]) / fit.sigma[0] ** 2) < 1e-3 * (1 + abs(slope))
        sd = 1 / np.sqrt(-curvature + 1 / fit.sigma[0] ** 2)
        assert row.ci_high == pytest.approx(60 * special.expit(x + stats.norm.ppf(0.975) * sd), rel=1e-3)


# ---------------------------------------------------------------------------------------------- transforms, input

def test_transforms_round_trip_and_keep_estimates_inside_bounds():
    t = Transforms({"a": (0.0, 1.0), "b": (2.0, np.inf), "c": (-np.inf, -1.0), "d": FREE, "e": (-3.0, 20.0)})
    assert t.kinds == ["logit", "log", "neglog", "identity", "logit"]
    x = np.random.default_rng(0).normal(0, 6, (500, 5))
    theta = t.to_own(x)
    assert np.all((theta[:, 0] > 0) & (theta[:, 0] < 1) & (theta[:, 1] > 2) & (theta[:, 2] < -1))
    np.testing.assert_allclose(t.to_unbounded(theta), x, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(t.to_own(t.to_unbounded(theta)), theta, rtol=1e-12)
    np.testing.assert_allclose(t.to_own([[0.0, 0.0, 0.0, 0.0, 0.0]]), [[0.5, 3.0, -2.0, 0.0, 8.5]])
    np.testing.assert_allclose(t.to_unbounded([[0.9, 2.5, -1.5, 4.0, 0.0]]),
                               [[np.log(9), np.log(0.5), np.log(0.5), 4.0, np.log(3 / 20)]])

    # data that push p to its upper bound (every one of 30 trials a success): estimates stay inside
    def coin(points):
        return 30 * np.log(points[:, 0])

    fit = fit_hierarchical([coin] * 5, {"p": (0.0, 1.0)}, n_obs=[30] * 5, vectorised=True)
    sub = fit.subjects
    assert ((sub["estimate"] > 0) & (sub["estimate"] < 1)).all() and sub["estimate"].min() > 0.9
    assert ((sub["ci_low"] >= 0) & (sub["ci_high"] <= 1)).all()
    assert (0 <= fit.group[["mean", "ci_low", "ci_high"]].to_numpy()).all()
    assert (fit.group[["mean", "ci_low", "ci_high"]].to_numpy() <= 1).all()


def test_the_log_scale_group_table_matches_the_log_normal():
    t = Transforms({"k": (1.0, np.inf)})
    table = _group_table(t, np.array([0.4]), np.array([0.7]), np.array([0.1]), 1.96)
    mean = lambda m: 1 + np.exp(m + 0.7**2 / 2)  # noqa: E731
    np.testing.assert_allclose(table.loc[0, ["mean", "sd", "ci_low", "ci_high"]].to_numpy(dtype=float),
                               [mean(0.4), np.sqrt((np.exp(0.49) - 1) * np.exp(0.8 + 0.49)), mean(0.4 - 0.196),
                                mean(0.4 + 0.196)], rtol=1e-10)


def test_bad_input_is_refused_with_one_line():
    with pytest.raises(ConfigError, match="key 'a': expected low < high"):
        Transforms({"a": (1.0, 0.0)})
    with pytest.raises(ConfigError, match="n_obs"):
        fit_hierarchical([lambda p: 0.0], {"a": FREE})
    with pytest.raises(ConfigError, match="key 'loglik': expected a log-likelihood that is finite or -inf"):
        fit_hierarchical([lambda p: np.nan], {"a": FREE}, n_obs=[3])
    with pytest.raises(ConfigError, match="a start where the observed data are possible"):
        fit_hierarchical([lambda p: -np.inf], {"a": FREE}, n_obs=[3])
