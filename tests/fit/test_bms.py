"""Random-effects BMS against cases computable by hand or by integration."""

from __future__ import annotations

import numpy as np
from scipy import integrate, special

from neurocur.fit.bms import bms, exceedance


def test_exceedance_of_two_models_is_a_beta_tail_and_of_three_matches_sampling():
    for a in ([3.0, 5.0], [1.0, 1.0], [12.5, 2.0]):
        assert abs(exceedance(a)[0] - special.betainc(a[1], a[0], 0.5)) < 1e-8  # P(r1 > 1/2), r1 ~ Beta(a1, a2)
    alpha = np.array([4.0, 2.5, 6.0])
    r = np.random.default_rng(0).dirichlet(alpha, size=400_000)
    sampled = np.bincount(r.argmax(axis=1), minlength=3) / len(r)
    np.testing.assert_allclose(exceedance(alpha), sampled, atol=3e-3)


def test_decisive_evidence_gives_the_exact_posterior_evidence_and_omnibus_risk():
    """When every data set's evidence picks one model (others 60 nats worse), q(m) is exact: alpha = 1 +
    counts, F1 = sum L + log B(alpha) - log B(1), and BOR = 1 / (1 + exp(F1 - F0)) with F0 = sum L - n log K."""
    picks = np.array([0] * 7 + [1] * 2 + [2] * 1)
    L = np.full((10, 3), -100.0)
    L[np.arange(10), picks] = -40.0
    result = bms(L)
    counts = np.bincount(picks, minlength=3)
    np.testing.assert_allclose(result.alpha, 1 + counts, atol=1e-12)

    def log_beta(a):
        return special.gammaln(a).sum() - special.gammaln(a.sum())

    f1 = -400.0 + log_beta(1.0 + counts) - log_beta(np.ones(3))
    f0 = -400.0 - 10 * np.log(3)
    assert abs(result.f1 - f1) < 1e-9 and abs(result.f0 - f0) < 1e-9
    assert abs(result.bor - 1 / (1 + np.exp(f1 - f0))) < 1e-12
    np.testing.assert_allclose(result.pxp, (1 - result.bor) * exceedance(1 + counts) + result.bor / 3, atol=1e-12)
    assert result.xp[0] > result.pxp[0] > 0.5  # the protection shrinks the winner towards 1/K
    table = result.table(["a", "b", "c"])  # a row per model, in the evidences' column order
    assert list(table["model"]) == ["a", "b", "c"] and (table["bor"] == result.bor).all()
    np.testing.assert_array_equal(table[["expected", "xp", "pxp"]].to_numpy().T, [result.expected, result.xp, result.pxp])


def test_the_free_energy_bounds_the_exact_evidence_from_integration():
    """Two models: the exact random-effects evidence is int prod_n (r e^L1 + (1 - r) e^L2) dr under a flat prior."""
    L = np.array([[-3.0, -4.0], [-2.0, -2.5], [-5.0, -3.0], [-1.0, -3.0]])
    exact = np.log(integrate.quad(lambda r: np.prod(r * np.exp(L[:, 0]) + (1 - r) * np.exp(L[:, 1])), 0, 1,
                                  epsabs=1e-14)[0])
    result = bms(L)
    assert result.f1 <= exact + 1e-12 and exact - result.f1 < 0.5  # the mean-field gap: here 0.35 nats
    # with no information at all, every model is as likely: xp and pxp are uniform
    flat = bms(np.zeros((6, 4)))
    np.testing.assert_allclose(flat.xp, 0.25, atol=1e-8)
    np.testing.assert_allclose(flat.pxp, 0.25, atol=1e-8)
