"""Maximum likelihood and profile intervals against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import special, stats

from neurocur.config import ConfigError
from neurocur.fit.mle import fit_ml, fit_table


class Stand:
    """A replay stand-in's interface: the log-likelihood of one theta, or an array of them for a list."""

    def loglik(self, theta, mask=None):
        if isinstance(theta, list):
            return np.array([self.loglik(t, mask) for t in theta])
        return self.at(theta)


class Coin(Stand):
    """A replay stand-in: k disengages in n decisions at a constant P(disengage) = p (key "LC.p")."""

    def __init__(self, k, n):
        self.k, self.n_obs = k, n

    def at(self, theta):
        p = theta["LC.p"]
        with np.errstate(divide="ignore"):
            return special.xlogy(self.k, p) + special.xlog1py(self.n_obs - self.k, -p)


class Gauss(Stand):
    """log L = -(a - 1)^2 / 2 s_a^2 - (b + 2)^2 / 2 s_b^2: intervals 1 +- 1.96 s_a, -2 +- 1.96 s_b."""

    n_obs = 100

    def at(self, theta):
        return -(theta["a"] - 1) ** 2 / (2 * 0.3**2) - (theta["b"] + 2) ** 2 / (2 * 0.1**2)


def test_the_estimate_and_its_profile_interval_match_the_closed_form():
    fit = fit_ml(Coin(30, 100), {"LC.p": (1e-6, 1 - 1e-6)}, starts=3)
    assert abs(fit.estimate["LC.p"] - 0.3) < 1e-5
    lo, hi = fit.ci["LC.p"]
    ll = Coin(30, 100).loglik
    for end in (lo, hi):  # the ends sit where the log-likelihood has dropped by chi2(1, .95) / 2
        assert abs(ll({"LC.p": 0.3}) - ll({"LC.p": end}) - stats.chi2.ppf(0.95, 1) / 2) < 1e-4
    assert 0.21 < lo < 0.3 < hi < 0.4
    assert abs(fit.aic - (2 - 2 * fit.loglik)) < 1e-12 and abs(fit.bic - (np.log(100) - 2 * fit.loglik)) < 1e-12


def test_two_parameters_and_pooling():
    fit = fit_ml(Gauss(), {"a": (-5, 5), "b": (-5, 5)})
    np.testing.assert_allclose([fit.estimate["a"], fit.estimate["b"]], [1, -2], atol=1e-4)
    np.testing.assert_allclose(fit.ci["a"], [1 - 1.96 * 0.3, 1 + 1.96 * 0.3], atol=2e-3)
    np.testing.assert_allclose(fit.ci["b"], [-2 - 1.96 * 0.1, -2 + 1.96 * 0.1], atol=2e-3)
    pooled = fit_ml([Coin(10, 50), Coin(40, 50)], {"LC.p": (0.01, 0.99)}, ci=None)
    assert abs(pooled.estimate["LC.p"] - 0.5) < 1e-5 and pooled.n_obs == 100
    table = fit_table([fit, pooled])
    assert list(table.columns) == ["dataset", "param", "estimate", "ci_low", "ci_high"] and len(table) == 3


def test_an_interval_reaching_its_bound_is_censored_there_and_impossible_starts_are_left():
    fit = fit_ml(Coin(0, 20), {"LC.p": (0.0, 0.5)})  # every decision engage: the estimate is p = 0
    assert fit.estimate["LC.p"] < 1e-6 and fit.ci["LC.p"][0] == 0.0 and fit.ci["LC.p"][1] < 0.2
    with pytest.raises(ConfigError, match="finite LOW < HIGH"):
        fit_ml(Coin(1, 2), {"LC.p": (0.5, 0.1)})


class Plateau(Stand):
    """Impossible (-inf) for p > 0.3, a binomial log-likelihood (k = 5 of 50) below: the midpoint start
    lies on the plateau."""

    n_obs = 50

    def at(self, theta):
        p = theta["LC.p"]
        return -np.inf if p > 0.3 else float(special.xlogy(5, p) + special.xlog1py(45, -p))


def test_a_start_is_never_on_an_impossible_plateau():
    fit = fit_ml(Plateau(), {"LC.p": (0.01, 0.99)}, starts=1, ci=None)
    assert abs(fit.estimate["LC.p"] - 0.1) < 1e-4 and np.isfinite(fit.loglik)


class TwoPeaks(Stand):
    """A low broad peak at 0.5 (log L 0), around the bounds' midpoint, and a higher narrow one at -4 (log L 3)."""

    n_obs = 10

    def at(self, theta):
        x = theta["a"]
        return float(np.logaddexp(-(x - 0.5) ** 2 / 2, 3 - (x + 4) ** 2 / (2 * 0.2**2)))


def test_the_starts_come_from_a_design_so_one_start_finds_the_higher_peak():
    """From the midpoint alone L-BFGS-B climbs the near, lower peak; the best point of the design is on the far one."""
    from scipy import optimize

    near = optimize.minimize(lambda x: -TwoPeaks().at({"a": x[0]}), [0.0], method="L-BFGS-B", bounds=[(-5, 5)])
    assert abs(near.x[0] - 0.5) < 1e-3
    fit = fit_ml(TwoPeaks(), {"a": (-5.0, 5.0)}, starts=1, ci=None)
    assert abs(fit.estimate["a"] + 4) < 1e-3 and abs(fit.loglik - 3) < 1e-4
    again = fit_ml(TwoPeaks(), {"a": (-5.0, 5.0)}, starts=1, ci=None)
    assert again.estimate == fit.estimate  # seeded design: the same fit
