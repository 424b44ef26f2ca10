"""Maximum likelihood on replays: bounded, several starts, per data set or pooled; profile-likelihood intervals.

The objective is the replayed log-likelihood (:meth:`neurocur.fit.replay.Replay.loglik`),
maximised with scipy's L-BFGS-B inside the bounds from ``starts`` points: the log-likelihood
is first evaluated on a space-filling design (the bounds' midpoint and :data:`DESIGN` points of
a scrambled Sobol sequence, seeded; one vectorised call on a cached replay), and the optimiser
starts from its ``starts`` best points; the best end point wins. A likelihood with a ridge
(the softmax gain against eq 14's alpha) has local optima that one start from the midpoint
can miss; a start where the observed decisions are impossible (-inf) lies on a flat plateau
the optimiser cannot leave, and is never among the best while the design has a finite point.
A theta where they are impossible costs a large constant, not NaN.

Intervals are profile-likelihood intervals (Wilks' theorem): the values of parameter k
whose profile log-likelihood, maximised over the other parameters, lies within
chi2(1, level) / 2 of the maximum; an end that reaches its bound is reported at the bound
(the interval is censored there). Information criteria: AIC = 2k - 2 log L, BIC = k log n - 2 log L.

Identifiability (``identify=True``, :func:`weak_keys`): the observed information, the Hessian of
-log L at the estimate by central finite differences on the bounded scale (each parameter's
bounds mapped to [0, 1]; one vectorised evaluation), inverted gives the Wald covariance. A key
whose Wald 95 % interval, +-1.96 sqrt(variance), is wider than its bounds is not identified by the
data within them, and neither is a key whose Wald correlation with such a key is at least
:data:`TIED` (they trade off along one direction). Two parameters that act only as a product have
a singular information matrix on their ridge (its null eigenvalue is taken as 1e-9 of the largest),
so both are named wherever on the ridge the estimate lies. Those keys are :attr:`MLFit.unidentified`,
and so is a key whose profile interval spans its whole bounds (a flat profile).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize, stats

from ..config import ConfigError

__all__ = ["MLFit", "fit_ml", "fit_table", "weak_keys"]

#: what an impossible theta costs instead of +inf
IMPOSSIBLE = 1e12
#: points of the scrambled Sobol design the starts are chosen from (a power of 2)
DESIGN = 64
#: chi2(1, .95) = 1.96^2: a key is identified when 1.96^2 times its Wald variance on the bounded scale is below 1
IDENTIFIED = float(stats.chi2.ppf(0.95, 1))
#: the Wald correlation with an unidentified key at which a key is not identified either (they trade off)
TIED = 0.99
#: the finite-difference step of the observed information, on the bounded scale
STEP = 1e-3


@dataclass
class MLFit:
    """A maximum-likelihood fit (:func:`fit_ml`).

    Parameters
    ----------
    dataset : str
        The data set's name (``pooled`` for a pooled fit).
    estimate : dict of str to float
        The estimate, by key.
    loglik : float
        The maximised log-likelihood.
    n_obs : int
        The scored observations (BIC's n).
    ci : dict of str to (float, float)
        The profile-likelihood intervals, by key (empty without).
    unidentified : list of str
        The keys the data do not identify within the bounds (module docstring); empty unless asked for.
    """

    dataset: str
    estimate: dict
    loglik: float
    n_obs: int
    ci: dict = field(default_factory=dict)
    #: the keys the data do not identify within the bounds (module docstring); empty unless asked for
    unidentified: list = field(default_factory=list)

    @property
    def n_params(self) -> int:
        return len(self.estimate)

    @property
    def aic(self) -> float:
        return 2 * self.n_params - 2 * self.loglik

    @property
    def bic(self) -> float:
        return self.n_params * np.log(self.n_obs) - 2 * self.loglik

    def summary(self) -> dict:
        return {"dataset": self.dataset, "loglik": self.loglik, "n_params": self.n_params, "n_obs": self.n_obs,
                "aic": self.aic, "bic": self.bic}


def _check_bounds(bounds: Mapping[str, tuple[float, float]]) -> tuple[list[str], np.ndarray]:
    keys = list(bounds)
    if not keys:
        raise ConfigError("--bounds", None, "at least one parameter to fit", "none")
    b = np.array([bounds[k] for k in keys], dtype=np.float64)
    for k, (lo, hi) in zip(keys, b):
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ConfigError("--bounds", k, "finite LOW < HIGH", f"{lo}:{hi}")
    return keys, b


def fit_ml(replays, bounds: Mapping[str, tuple[float, float]], *, starts: int = 5, seed: int = 0,
           ci: float | None = 0.95, dataset: str = "pooled", mask=None, identify: bool = False) -> MLFit:
    """One theta maximising the summed log-likelihood of ``replays``.

    Without bounds, the model has no free parameter: its log-likelihood is evaluated.

    Parameters
    ----------
    replays : Replay or sequence of Replay
        One data set, or several pooled (anything with ``loglik(list of {key: value})`` and ``n_obs``, such as
        a :class:`~neurocur.fit.hierarchical.Subject`).
    bounds : mapping of str to (float, float)
        ``{"REGION.param": (low, high)}``: the fitted keys and their bounds (-inf/inf for none).
    starts : int
        Local searches (L-BFGS-B), from the best points of a seeded Sobol design.
    seed : int
        The design's seed.
    ci : float or None
        The level of the profile-likelihood intervals; None for none.
    dataset : str
        The name in the fit's rows.
    mask : array of bool, optional
        Only the episodes it selects are scored (one replay; held-out scores).
    identify : bool
        Also check which keys the data leave unidentified (:attr:`MLFit.unidentified`).

    Returns
    -------
    MLFit
        The estimate, its intervals, the log-likelihood, AIC and BIC.
    """
    replays = [replays] if not isinstance(replays, Sequence) else list(replays)
    n_obs = int(sum(r.n_obs for r in replays)) if mask is None else \
        int(sum(r.n_scored(mask) if hasattr(r, "n_scored") else np.sum(mask) for r in replays))

    def loglik_many(points) -> np.ndarray:
        thetas = [dict(zip(keys, map(float, x))) for x in points]
        return np.sum([np.asarray(r.loglik(thetas, mask), dtype=np.float64) for r in replays], axis=0)

    def loglik(x) -> float:
        return float(loglik_many([x])[0])

    if not bounds:
        keys = []
        return MLFit(dataset, {}, loglik([]), n_obs)
    keys, b = _check_bounds(bounds)

    def cost(x) -> float:
        ll = loglik(x)
        return IMPOSSIBLE if ll == -np.inf else -ll

    unit = stats.qmc.Sobol(len(keys), rng=np.random.default_rng(seed)).random_base2(int(np.log2(DESIGN)))
    design = np.vstack([b.mean(axis=1), stats.qmc.scale(unit, b[:, 0], b[:, 1])])
    values = loglik_many(design)
    order = [i for i in np.argsort(-values, kind="stable")[:max(1, starts)] if values[i] > -np.inf]
    if not order:  # no point of the design gives every observed decision a chance
        return MLFit(dataset, dict(zip(keys, map(float, design[0]))), -np.inf, n_obs)
    best = min((optimize.minimize(cost, design[i], method="L-BFGS-B", bounds=b) for i in order),
               key=lambda r: r.fun)
    x = np.clip(best.x, b[:, 0], b[:, 1])
    fit = MLFit(dataset, dict(zip(keys, map(float, x))), loglik(x), n_obs)
    if ci is not None:
        fit.ci = {k: profile_interval(cost, x, b, i, -fit.loglik, ci) for i, k in enumerate(keys)}
    if identify:
        flat = [k for k, (lo, hi) in fit.ci.items() if (lo, hi) == tuple(bounds[k])]
        weak = weak_keys(loglik_many, x, b, keys)
        fit.unidentified = [k for k in keys if k in flat or k in weak]
    return fit


def weak_keys(loglik_many, x: np.ndarray, b: np.ndarray, keys: Sequence[str]) -> list[str]:
    """The keys whose Wald 95 % interval at ``x`` is wider than their bounds, and those correlated with one by at
    least :data:`TIED` (module docstring): on the bounded scale, a variance (the diagonal of the inverse
    observed information) above 1 / :data:`IDENTIFIED`; an eigenvalue of the information that is not positive
    (a flat direction) counts as 1e-9 of the largest.
    Empty when a point of the stencil is impossible (no curvature to read).

    Parameters
    ----------
    loglik_many : callable
        ``loglik_many(points)``: the log-likelihood of each point (the rows of an array, on the parameters'
        own scale).
    x : array of shape (keys,)
        The point, on the parameters' own scale.
    b : array of shape (keys, 2)
        Each key's bounds (low, high).
    keys : sequence of str
        The fitted keys, in ``x``'s order.

    Returns
    -------
    list of str
        The weak keys, in ``keys``' order.
    """
    d, width = len(keys), b[:, 1] - b[:, 0]
    h = STEP
    centre = np.clip((x - b[:, 0]) / width, h, 1.0 - h)  # the stencil inside the bounds
    eye = np.eye(d) * h
    offsets = [np.zeros(d)] + [s * eye[i] for i in range(d) for s in (1, -1)]
    offsets += [si * eye[i] + sj * eye[j] for i in range(d) for j in range(i + 1, d) for si in (1, -1) for sj in (1, -1)]
    values = -np.asarray(loglik_many(b[:, 0] + (centre + np.array(offsets)) * width), dtype=np.float64)
    if not np.isfinite(values).all():
        return []
    f0, hess, k = values[0], np.empty((d, d)), 1 + 2 * d
    for i in range(d):
        hess[i, i] = (values[1 + 2 * i] - 2 * f0 + values[2 + 2 * i]) / h**2
        for j in range(i + 1, d):
            pp, pm, mp, mm = values[k:k + 4]
            hess[i, j] = hess[j, i] = (pp - pm - mp + mm) / (4 * h**2)
            k += 4
    eigenvalues, vectors = np.linalg.eigh(hess)
    floor = 1e-9 * max(float(np.abs(eigenvalues).max()), 1.0)
    covariance = (vectors / np.maximum(eigenvalues, floor)) @ vectors.T
    variance = np.diag(covariance)
    weak = IDENTIFIED * variance > 1.0
    correlation = covariance / np.sqrt(np.outer(variance, variance))
    tied = (np.abs(correlation[:, weak]) >= TIED).any(axis=1)
    return [key for key, w, t in zip(keys, weak, tied) if w or t]


def profile_interval(cost, x: np.ndarray, b: np.ndarray, i: int, best: float, level: float) -> tuple[float, float]:
    """The profile-likelihood interval of parameter ``i`` at ``level`` around the minimum ``best`` of ``cost`` at ``x``."""
    rise = stats.chi2.ppf(level, 1) / 2.0
    others = [j for j in range(len(x)) if j != i]

    def profile(v: float) -> float:
        if not others:
            return cost(np.array([v]))
        def inner(y):
            z = x.copy()
            z[i], z[others] = v, y
            return cost(z)
        return optimize.minimize(inner, x[others], method="L-BFGS-B", bounds=b[others]).fun

    def gap(v: float) -> float:
        return profile(v) - best - rise

    ends = []
    for bound in (b[i, 0], b[i, 1]):
        if x[i] == bound or gap(bound) <= 0:
            ends.append(float(bound))
        else:
            ends.append(float(optimize.brentq(gap, x[i], bound, xtol=1e-6 * (b[i, 1] - b[i, 0]))))
    return ends[0], ends[1]


def fit_table(fits: Sequence[MLFit]) -> pd.DataFrame:
    """The tidy table of fits: ``dataset, param, estimate, ci_low, ci_high``.

    Parameters
    ----------
    fits : sequence of MLFit
        The fits, one row per fit and key.

    Returns
    -------
    pandas.DataFrame
        One row per fit and key.
    """
    rows = [{"dataset": f.dataset, "param": k, "estimate": v, "ci_low": f.ci.get(k, (np.nan, np.nan))[0],
             "ci_high": f.ci.get(k, (np.nan, np.nan))[1]} for f in fits for k, v in f.estimate.items()]
    return pd.DataFrame(rows, columns=["dataset", "param", "estimate", "ci_low", "ci_high"])
