"""A subject's Laplace approximation under a Gaussian prior, the sampled group evidence and the iBIC, against the
closed forms of a Gaussian linear model (where the Laplace approximation is exact)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from neurocur.config import ConfigError
from neurocur.fit.evidence import checked_loglik, integrated_bic, posterior_mode, sampled_evidence
from neurocur.fit.transforms import Transforms

FREE = (-np.inf, np.inf)
MU, VAR = np.array([0.3, -0.5]), np.array([0.8, 2.0])


def line_subject(seed, n=25):
    """y_j ~ N(a + b t_j, 1): its design matrix, data and vectorised log-likelihood of (a, b)."""
    rng = np.random.default_rng(seed)
    design = np.column_stack([np.ones(n), np.linspace(-1.0, 2.0, n)])
    y = design @ np.array([0.6, -1.1]) + rng.standard_normal(n)
    return design, y, lambda points: stats.norm.logpdf(y[None, :], points @ design.T, 1.0).sum(axis=1)


def exact_posterior(design, y):
    """The posterior of (a, b) under N(MU, diag VAR) and the exact log marginal likelihood."""
    precision = design.T @ design + np.diag(1 / VAR)
    cov = np.linalg.inv(precision)
    mean = cov @ (design.T @ y + MU / VAR)
    evidence = stats.multivariate_normal(design @ MU, np.eye(len(y)) + design @ np.diag(VAR) @ design.T).logpdf(y)
    return mean, cov, evidence


def starts_for(seed, k=2, d=16):
    return np.vstack([MU, MU + np.sqrt(VAR) * np.random.default_rng(seed).standard_normal((d, k))])


def test_the_laplace_posterior_and_evidence_of_a_gaussian_subject_are_exact():
    design, y, f = line_subject(0)
    mean, cov, exact = exact_posterior(design, y)
    assert abs(cov[0, 1]) > 0.1 * np.sqrt(cov[0, 0] * cov[1, 1])  # a correlated posterior: the cross term counts
    t = Transforms({"a": FREE, "b": FREE})
    x, v, evidence = posterior_mode(f, t, MU, VAR, starts_for(1), None, 3, "s0")
    np.testing.assert_allclose(x, mean, atol=1e-6)
    np.testing.assert_allclose(v, cov, rtol=1e-5, atol=1e-8)
    assert abs(evidence - exact) < 1e-6
    # a warm start far from the MAP reaches the same point
    x2, _, evidence2 = posterior_mode(f, t, MU, VAR, starts_for(2), mean + 3.0, 3, "s0")
    np.testing.assert_allclose(x2, mean, atol=1e-6)
    assert abs(evidence2 - exact) < 1e-6


def test_the_sampled_evidence_matches_the_exact_one_within_its_standard_error():
    subjects = [line_subject(seed) for seed in range(3)]
    exact = sum(exact_posterior(design, y)[2] for design, y, _ in subjects)
    t = Transforms({"a": FREE, "b": FREE})
    total, mcse = sampled_evidence([f for *_, f in subjects], t, MU, VAR, 20000, 7, ["s0", "s1", "s2"])
    assert 0 < mcse < 0.1 and abs(total - exact) < 4 * mcse, (total, exact, mcse)
    # the same seed draws the same samples; the standard error shrinks as 1/sqrt(n_samples)
    assert sampled_evidence([f for *_, f in subjects], t, MU, VAR, 20000, 7, ["s0", "s1", "s2"]) == (total, mcse)
    _, mcse_small = sampled_evidence([f for *_, f in subjects], t, MU, VAR, 2000, 7, ["s0", "s1", "s2"])
    assert 2.0 < mcse_small / mcse < 4.5


def test_the_integrated_bic_charges_log_n_per_group_parameter():
    assert integrated_bic(-100.0, 4, 50) == pytest.approx(200.0 + 4 * np.log(50), rel=1e-15)
    assert integrated_bic(-100.0, 0, 50) == 200.0


def test_an_untrustworthy_or_impossible_log_likelihood_is_refused_with_one_line():
    points = np.zeros((2, 1))
    with pytest.raises(ConfigError, match=r"^s1: key 'loglik': expected a log-likelihood that is finite or -inf"):
        checked_loglik(lambda p: np.array([0.0, np.inf]), points, "s1")
    t = Transforms({"a": FREE})
    impossible = lambda p: np.full(len(p), -np.inf)  # noqa: E731
    with pytest.raises(ConfigError, match="a start where the observed data are possible"):
        posterior_mode(impossible, t, MU[:1], VAR[:1], starts_for(0, k=1), None, 3, "s2")
    with pytest.raises(ConfigError, match="a sample of the group prior where the data are possible"):
        sampled_evidence([impossible], t, MU[:1], VAR[:1], 10, 0, ["s2"])
