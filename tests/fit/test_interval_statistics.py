"""The statistics around the fitted models against closed forms and hand-made tables: the profile-likelihood
interval where two parameters trade off, the bootstrap's and the posterior's percentile intervals on samples
whose quantiles are known exactly, and the recovery summary's bias and coverage.

Each tolerance separates the right answer from a plausible wrong one: the profile interval from the
conditional one (the other parameters held at the best fit), a 95 % interval from a 90 % one, coverage of
the truth from coverage of the estimate, and the bias from its negative.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from neurocur.fit.bootstrap import percentile_interval
from neurocur.fit.mle import fit_ml, profile_interval
from neurocur.fit.recovery import recovery_summary
from neurocur.fit.sbi import posterior_table

#: sqrt(chi2(1, 0.95)) = the 97.5 % normal quantile, 1.95996...
Z95 = float(np.sqrt(stats.chi2.ppf(0.95, 1)))


class Correlated:
    """A replay stand-in with a bivariate Gaussian log-likelihood: mean (1, -2), standard deviations (0.3, 0.1),
    correlation 0.8 (a ridge, as the softmax gain and eq 14's alpha make one). The profile of a (b re-fitted at
    every a) is -(a - 1)^2 / 2 s_a^2, so a's 95 % interval is 1 +- 1.96 s_a; with b held at its best fit it would
    be 1 +- 1.96 s_a sqrt(1 - rho^2), 0.6 times as wide."""

    n_obs = 100
    mean, sd, rho = np.array([1.0, -2.0]), np.array([0.3, 0.1]), 0.8

    def __init__(self):
        cov = np.outer(self.sd, self.sd) * np.array([[1.0, self.rho], [self.rho, 1.0]])
        self.precision = np.linalg.inv(cov)

    def at(self, x) -> float:
        z = np.asarray(x, dtype=np.float64) - self.mean
        return float(-0.5 * z @ self.precision @ z)

    def loglik(self, theta, mask=None):
        if isinstance(theta, list):
            return np.array([self.loglik(t, mask) for t in theta])
        return self.at([theta["a"], theta["b"]])


def test_a_profile_interval_refits_the_other_parameter_along_a_ridge():
    g = Correlated()
    profile = {k: (m - Z95 * s, m + Z95 * s) for k, m, s in zip("ab", g.mean, g.sd)}
    conditional = {k: (m - Z95 * s * np.sqrt(1 - g.rho**2), m + Z95 * s * np.sqrt(1 - g.rho**2))
                   for k, m, s in zip("ab", g.mean, g.sd)}
    fit = fit_ml(g, {"a": (-5.0, 5.0), "b": (-5.0, 5.0)}, starts=2)
    np.testing.assert_allclose([fit.estimate["a"], fit.estimate["b"]], g.mean, atol=1e-4)
    for k in "ab":  # the two answers differ by 0.4 * 1.96 s (0.24 for a, 0.08 for b): far beyond 2e-3
        np.testing.assert_allclose(fit.ci[k], profile[k], atol=2e-3)
        assert abs(fit.ci[k][1] - conditional[k][1]) > 0.05
    # the function itself, on the cost -log L at the closed-form minimum
    b = np.array([[-5.0, 5.0], [-5.0, 5.0]])
    np.testing.assert_allclose(profile_interval(lambda x: -g.at(x), g.mean.copy(), b, 0, 0.0, 0.95),
                               profile["a"], atol=2e-3)
    # at 90 % the interval is 1 +- 1.645 s_a: the level reaches the profile
    np.testing.assert_allclose(profile_interval(lambda x: -g.at(x), g.mean.copy(), b, 0, 0.0, 0.90),
                               1 + np.array([-1, 1]) * stats.norm.ppf(0.95) * 0.3, atol=2e-3)


def test_the_bootstrap_percentile_interval_takes_the_central_quantiles_of_its_level():
    # np.arange(1001): the q quantile is exactly 1000 q, so 95 % is (25, 975) and 90 % would be (50, 950)
    np.testing.assert_allclose(percentile_interval(np.arange(1001), 0.95), [25.0, 975.0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(percentile_interval(np.arange(1001), 0.90), [50.0, 950.0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(percentile_interval(np.arange(1001)[::-1], 0.5), [250.0, 750.0], rtol=0, atol=1e-9)
    # a standard normal sample at its mid-quantiles: +-1.960 at 95 % (1.645 at 90 %, 0.3 away)
    n = 100_000
    normal = stats.norm.ppf((np.arange(n) + 0.5) / n)
    np.testing.assert_allclose(percentile_interval(normal), [-Z95, Z95], atol=1e-3)


def test_the_posterior_table_gives_the_median_and_the_central_95_percent_interval():
    # two parameters with known quantiles: column 0 is 0, 0.001, ..., 1; column 1 is 10 times it, reversed
    grid = np.arange(1001) / 1000
    samples = np.column_stack([grid, 10 * grid[::-1]])
    table = posterior_table(samples, {"a": (0.0, 1.0), "b": (0.0, 10.0)}, "obs")
    assert list(table["param"]) == ["a", "b"] and (table["dataset"] == "obs").all()
    np.testing.assert_allclose(table["estimate"], [0.5, 5.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(table["ci_low"], [0.025, 0.25], rtol=0, atol=1e-12)  # 90 %: 0.05, 0.5
    np.testing.assert_allclose(table["ci_high"], [0.975, 9.75], rtol=0, atol=1e-12)  # 90 %: 0.95, 9.5


@pytest.fixture
def recovered():
    """Five data sets of two parameters. Every estimate lies inside its own interval; the truth lies inside
    for three of the five of "a" (d0, d2, d4) and for one of the five of "b" (d3). "a" is overestimated by
    0.2 on average, "b" underestimated by 0.5."""
    a = pd.DataFrame({"true": [1.0, 2.0, 3.0, 4.0, 5.0], "estimate": [1.1, 2.6, 3.0, 4.5, 4.8],
                      "ci_low": [0.8, 2.3, 2.7, 4.2, 4.5], "ci_high": [1.4, 2.9, 3.3, 4.8, 5.1]})
    b = pd.DataFrame({"true": [0.0, 1.0, 2.0, 3.0, 4.0], "estimate": [-0.5, 0.5, 1.0, 2.9, 3.6],
                      "ci_low": [-0.8, 0.2, 0.7, 2.6, 3.3], "ci_high": [-0.2, 0.8, 1.3, 3.2, 3.9]})
    table = pd.concat([t.assign(param=p, dataset=[f"d{i}" for i in range(5)], loglik=-10.0)
                       for p, t in (("a", a), ("b", b))], ignore_index=True)
    return table[["dataset", "param", "true", "estimate", "ci_low", "ci_high", "loglik"]]


def test_recovery_coverage_counts_the_intervals_that_hold_the_truth(recovered):
    assert ((recovered["ci_low"] <= recovered["estimate"]) & (recovered["estimate"] <= recovered["ci_high"])).all()
    summary = recovery_summary(recovered).set_index("param")
    assert summary.loc["a", "coverage"] == pytest.approx(3 / 5, abs=1e-12)  # not 1, the estimate's own
    assert summary.loc["b", "coverage"] == pytest.approx(1 / 5, abs=1e-12)
    assert list(summary["n"]) == [5, 5]


def test_recovery_bias_is_the_mean_estimate_minus_the_truth(recovered):
    summary = recovery_summary(recovered).set_index("param")
    assert summary.loc["a", "bias"] == pytest.approx(0.2, abs=1e-12)  # (0.1 + 0.6 + 0 + 0.5 - 0.2) / 5
    assert summary.loc["b", "bias"] == pytest.approx(-0.5, abs=1e-12)  # (-0.5 - 0.5 - 1 - 0.1 - 0.4) / 5
    assert summary.loc["a", "rmse"] == pytest.approx(np.sqrt((0.01 + 0.36 + 0 + 0.25 + 0.04) / 5), abs=1e-12)
    assert summary.loc["b", "rmse"] == pytest.approx(np.sqrt((0.25 + 0.25 + 1 + 0.01 + 0.16) / 5), abs=1e-12)
    for p in "ab":  # Pearson r, by its definition
        t = recovered[recovered["param"] == p]
        x, y = t["true"] - t["true"].mean(), t["estimate"] - t["estimate"].mean()
        assert summary.loc[p, "r"] == pytest.approx((x * y).sum() / np.sqrt((x**2).sum() * (y**2).sum()), abs=1e-12)
