"""Identifiability at the estimate: two parameters that act only as a product are flagged, two that act apart are
not (closed-form Bernoulli likelihoods, no circuit)."""

from __future__ import annotations

import numpy as np
from scipy.special import log_expit

from neurocur.fit.mle import fit_ml


class Logistic:
    """Choices y_t ~ Bernoulli(expit(eta_t)), eta_t = a b z_t (``product``) or a z_t + b w_t: a replay's
    vectorised ``loglik`` in closed form."""

    def __init__(self, product: bool, n: int = 400, seed: int = 0):
        rng = np.random.default_rng(seed)
        self.z, self.w = rng.normal(size=n), rng.normal(size=n)
        self.product, self.n_obs = product, n
        eta = self.eta(1.5, 2.0)
        self.y = rng.random(n) < 1.0 / (1.0 + np.exp(-eta))

    def eta(self, a, b):
        return a * b * self.z if self.product else a * self.z + b * self.w

    def loglik(self, theta, mask=None):
        many = isinstance(theta, list)
        values = [float(np.sum(log_expit(np.where(self.y, 1.0, -1.0) * self.eta(t["a"], t["b"]))))
                  for t in (theta if many else [theta])]
        return np.array(values) if many else values[0]


BOUNDS = {"a": (0.5, 4.0), "b": (0.5, 4.0)}


def test_a_product_is_not_identified_and_two_separate_effects_are():
    product = fit_ml(Logistic(product=True), BOUNDS, starts=2, ci=None, identify=True, dataset="s")
    assert product.unidentified == ["a", "b"]
    assert abs(product.estimate["a"] * product.estimate["b"] - 3.0) < 0.6  # the ridge a b = 3 is found
    apart = fit_ml(Logistic(product=False), BOUNDS, starts=2, ci=None, identify=True, dataset="s")
    assert apart.unidentified == []
    assert abs(apart.estimate["a"] - 1.5) < 0.5 and abs(apart.estimate["b"] - 2.0) < 0.6
    assert fit_ml(Logistic(product=True), BOUNDS, starts=2, ci=None, dataset="s").unidentified == []  # not asked


def test_the_threshold_is_a_wald_interval_as_wide_as_the_bounds():
    """One parameter with few observations: flagged exactly when its Wald 95 % interval is wider than its bounds
    (curvature on the bounded scale below 1.96 ** 2); the same model with many observations is not."""
    from neurocur.fit.mle import IDENTIFIED

    assert abs(IDENTIFIED - 1.959964 ** 2) < 1e-5

    class One:
        def __init__(self, n):
            self.n_obs = n

        def loglik(self, theta, mask=None):  # Gaussian mean, unit variance, sample mean 0.3: curvature n
            many = isinstance(theta, list)
            values = [-0.5 * self.n_obs * (t["m"] - 0.3) ** 2 for t in (theta if many else [theta])]
            return np.array(values) if many else values[0]

    # bounds of width 1: curvature n on the bounded scale
    assert fit_ml(One(3), {"m": (0.0, 1.0)}, starts=1, ci=None, identify=True).unidentified == ["m"]
    assert fit_ml(One(5), {"m": (0.0, 1.0)}, starts=1, ci=None, identify=True).unidentified == []


def test_the_fit_command_warns_of_novelty_scale_and_gain_fitted_together(tmp_path, capsys):
    """Count-based novelty, DA = scale / sqrt(N), enters the softmax only as gain * scale: fitted together, both are
    named in a warning line and in summary.json; the gain alone is identified."""
    import json

    import pandas as pd

    from neurocur.cli import main
    from neurocur.fit.study import condition_of, simulate

    experiment, condition = condition_of("fit_curiosity", "novelty")
    _, episodes = simulate(condition, {}, experiment.run_seed(0), 60)
    data = tmp_path / "choices.csv"
    pd.DataFrame({"dataset": "s", "episode": episodes["episode"], "context": episodes["context"],
                  "decision": episodes["action"]}).to_csv(data, index=False)
    argv = ["fit", str(data), "--experiment", "fit_curiosity", "--condition", "novelty", "--fit", "LC.gain",
            "--bounds", "LC.gain=0.1:10", "--starts", "2", "--out", str(tmp_path / "fit")]
    assert main([*argv, "--fit", "VTA.scale", "--bounds", "VTA.scale=0.1:10"]) == 0
    summary = json.loads((tmp_path / "fit" / "summary.json").read_text())
    assert summary["not_identified"] == {"s": ["LC.gain", "VTA.scale"]}
    assert summary["fits"][0]["not_identified"] == ["LC.gain", "VTA.scale"]
    err = capsys.readouterr().err
    assert "warning: data set 's': the data do not identify LC.gain, VTA.scale" in err
    assert main(argv) == 0
    summary = json.loads((tmp_path / "fit" / "summary.json").read_text())
    assert summary["not_identified"] == {} and summary["warnings"] == []
