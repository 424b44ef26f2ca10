"""A hierarchical fit's evidence: each subject by Laplace under the group prior, the group by sampling, the iBIC.

Huys, Cools, Gölzer, Friedel, Heinz, Dolan & Dayan (2011), PLoS Comput Biol 7:e1002028, methods.
Subject i's parameters x, on the unbounded scale of :mod:`neurocur.fit.transforms`, have the group
prior N(mu, diag(sigma^2)); theta = T(x) is what its log-likelihood log L_i takes.

**Laplace** (:func:`posterior_mode`, a hierarchical fit's E-step for one subject): the MAP m_i
maximises log L_i(T(x)) + log N(x; mu, sigma^2) (scipy's L-BFGS-B on x, each parameter of a bounded
scale kept within |x| <= :data:`BOX`; the likelihood's gradient by central differences, relative step
:data:`STEP_GRAD`, the prior's exact), and the Laplace posterior covariance V_i is the inverse of the
negative log-posterior's Hessian at m_i (the likelihood's part by central second differences, relative
step :data:`STEP_HESS`, in one vectorised call; the prior's 1/sigma^2 exact). Subject i's Laplace log
evidence is

    log L_i(T(m_i)) + log N(m_i; mu, sigma^2) + (k/2) log 2 pi + (1/2) log det V_i,

and their sum is the Laplace log p(D | mu, sigma) (what ``neurocur compare --hierarchical`` gives
random-effects BMS, a subject's term each).

**Sampling** (:func:`sampled_evidence`), as Huys et al. do: ``n_samples`` x_s ~ N(mu, sigma^2) from a
seeded Generator, the same for every subject, log p(D | mu, sigma) = sum_i log mean_s L_i(T(x_s)); its
Monte Carlo standard error by the delta method over the shared samples.

**iBIC** (:func:`integrated_bic`, Huys et al.'s integrated BIC): -2 log p(D | mu, sigma) + 2k log N, with k
fitted parameters (a mu and a sigma each) and N the total number of observations; lower is better.

A log-likelihood that is NaN or +inf is refused (:func:`checked_loglik`); -inf (data impossible at
theta) costs :data:`~neurocur.fit.mle.IMPOSSIBLE` in the MAP's search.
"""

from __future__ import annotations

import numpy as np
from scipy import optimize, special

from ..config import ConfigError
from .mle import IMPOSSIBLE
from .transforms import Transforms

__all__ = ["checked_loglik", "integrated_bic", "posterior_mode", "sampled_evidence"]

#: |x| bound on a logit or log scale (theta then stays inside its bounds)
BOX = 30.0
#: relative central-difference steps on x: the likelihood's gradient and its Hessian
STEP_GRAD, STEP_HESS = 1e-5, 1e-3


def checked_loglik(f, points: np.ndarray, name: str) -> np.ndarray:
    """log L at own-scale ``points``; NaN or +inf is refused (a number that cannot be trusted).

    Parameters
    ----------
    f : callable
        A subject's log-likelihood: (m, k) own-scale points to m values.
    points : numpy.ndarray
        (m, k) parameter vectors on the own scale.
    name : str
        The subject, named in the error.

    Returns
    -------
    numpy.ndarray
        (m,) log-likelihoods, each finite or -inf.

    Raises
    ------
    ConfigError
        When one is NaN or +inf, naming the subject and the point.
    """
    ll = f(points)
    bad = np.isnan(ll) | (ll == np.inf)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise ConfigError(name, "loglik", "a log-likelihood that is finite or -inf", f"{ll[i]} at theta = {points[i]}")
    return ll


def posterior_mode(f, transforms: Transforms, mu, var, design, warm, starts: int, name: str):
    """A subject's MAP m on x, its Laplace covariance V and its Laplace log evidence under N(mu, var) (module
    docstring).

    Without a warm start, L-BFGS-B starts from the ``starts`` best points of ``design`` by log-posterior (those
    where the data are possible); with one, from it and from the design points whose log-posterior already beats
    it (at most ``starts - 1``). The best end point wins.

    Parameters
    ----------
    f : callable
        The subject's log-likelihood: (m, k) own-scale points to m values.
    transforms : Transforms
        The fitted parameters' scales.
    mu : numpy.ndarray
        (k,) the prior's means on the unbounded scale.
    var : numpy.ndarray
        (k,) the prior's variances on the unbounded scale.
    design : numpy.ndarray
        (d, k) candidate starts on the unbounded scale.
    warm : numpy.ndarray or None
        (k,) the subject's previous MAP, or None in a first E-step.
    starts : int
        The most local searches.
    name : str
        The subject, named in an error.

    Returns
    -------
    tuple of (numpy.ndarray, numpy.ndarray, float)
        The MAP (k,), the Laplace covariance (k, k) and the Laplace log evidence, all on the unbounded scale.

    Raises
    ------
    ConfigError
        When the data are impossible at every start or around the MAP, when the log-likelihood is NaN or +inf
        (:func:`checked_loglik`), or when the MAP is not a maximum (a Hessian that is not positive definite).
    """
    k = len(mu)
    box = [(-BOX, BOX) if kind != "identity" else (None, None) for kind in transforms.kinds]

    def neg_ll(xs):  # -log L at unbounded points; an impossible point costs IMPOSSIBLE
        ll = checked_loglik(f, transforms.to_own(xs), name)
        return np.where(ll == -np.inf, IMPOSSIBLE, -ll)

    def cost(x):
        h = STEP_GRAD * np.maximum(1.0, np.abs(x))
        steps = np.diag(h)
        v = neg_ll(np.vstack([x, x + steps, x - steps]))
        r = x - mu
        return v[0] + 0.5 * np.sum(r**2 / var), (v[1:k + 1] - v[k + 1:]) / (2 * h) + r / var

    prior = 0.5 * np.sum((design - mu) ** 2 / var, axis=1)
    candidates = design if warm is None else np.vstack([warm, design])
    values = neg_ll(candidates) + (prior if warm is None else np.concatenate([[0.5 * np.sum((warm - mu) ** 2 / var)],
                                                                              prior]))
    order = np.argsort(values, kind="stable")
    if warm is None:
        chosen = [i for i in order[:starts] if values[i] < IMPOSSIBLE]
    else:
        chosen = [0] + [i for i in order[:starts - 1] if i != 0 and values[i] < values[0]]
    if not chosen:
        raise ConfigError(name, "loglik", "a start where the observed data are possible", "-inf at every start")
    best = min((optimize.minimize(cost, candidates[i], jac=True, method="L-BFGS-B", bounds=box,
                                  options={"ftol": 1e-12, "gtol": 1e-6, "maxiter": 500}) for i in chosen),
               key=lambda r: r.fun)
    x = best.x
    nll, hess = _hessian(neg_ll, x, name)
    precision = hess + np.diag(1.0 / var)
    try:
        chol = np.linalg.cholesky(precision)
    except np.linalg.LinAlgError:
        raise ConfigError(name, "theta", "a maximum of the log-posterior (a positive definite Hessian)",
                          f"a saddle or a flat direction at {transforms.to_own(x)}") from None
    cov = np.linalg.inv(precision)
    cov = (cov + cov.T) / 2
    log_det_precision = 2.0 * np.sum(np.log(np.diag(chol)))
    evidence = -nll - 0.5 * np.sum((x - mu) ** 2 / var) - 0.5 * np.sum(np.log(var)) - 0.5 * log_det_precision
    return x, cov, evidence


def _hessian(neg_ll, x: np.ndarray, name: str) -> tuple[float, np.ndarray]:
    """-log L at ``x`` and its Hessian by central (second) differences, every point in one call."""
    k = len(x)
    h = STEP_HESS * np.maximum(1.0, np.abs(x))
    e = np.diag(h)
    pairs = [(i, j) for i in range(k) for j in range(i + 1, k)]
    points = [x] + [x + e[i] for i in range(k)] + [x - e[i] for i in range(k)]
    for i, j in pairs:
        points += [x + e[i] + e[j], x + e[i] - e[j], x - e[i] + e[j], x - e[i] - e[j]]
    v = neg_ll(np.array(points))
    if np.any(v >= IMPOSSIBLE):
        raise ConfigError(name, "loglik", "the observed data possible at and around the MAP (its curvature)",
                          f"-inf near x = {points[int(np.argmax(v >= IMPOSSIBLE))]} (unbounded scale)")
    plus, minus = v[1:k + 1], v[k + 1:2 * k + 1]
    hess = np.diag((plus - 2 * v[0] + minus) / h**2)
    for n, (i, j) in enumerate(pairs):
        pp, pm, mp, mm = v[2 * k + 1 + 4 * n: 2 * k + 5 + 4 * n]
        hess[i, j] = hess[j, i] = (pp - pm - mp + mm) / (4 * h[i] * h[j])
    return float(v[0]), hess


def sampled_evidence(fns, transforms: Transforms, mu, var, n_samples: int, seed, names) -> tuple[float, float]:
    """sum_i log mean_s L_i(T(x_s)), x_s ~ N(mu, var) shared by every subject, and its delta-method
    standard error (the sum's derivative in subject i's sample mean is 1 / that mean).

    Parameters
    ----------
    fns : sequence of callable
        The subjects' log-likelihoods: (m, k) own-scale points to m values.
    transforms : Transforms
        The fitted parameters' scales.
    mu : numpy.ndarray
        (k,) the group prior's means on the unbounded scale.
    var : numpy.ndarray
        (k,) the group prior's variances on the unbounded scale.
    n_samples : int
        Draws from the group prior.
    seed : int or numpy.random.SeedSequence
        The draws' seed (``numpy.random.default_rng``).
    names : sequence of str
        The subjects, named in an error.

    Returns
    -------
    tuple of (float, float)
        The sampled log p(D | mu, sigma) and its Monte Carlo standard error (inf with one sample).

    Raises
    ------
    ConfigError
        When a subject's data are impossible at every sample, or its log-likelihood is NaN or +inf.
    """
    x = mu + np.sqrt(var) * np.random.default_rng(seed).standard_normal((n_samples, len(mu)))
    thetas = transforms.to_own(x)
    total, ratio = 0.0, np.zeros(n_samples)
    for f, name in zip(fns, names):
        ll = checked_loglik(f, thetas, name)
        log_mean = special.logsumexp(ll) - np.log(n_samples)
        if log_mean == -np.inf:
            raise ConfigError(name, "loglik", "a sample of the group prior where the data are possible",
                              f"-inf at all {n_samples}")
        total += log_mean
        ratio += np.exp(ll - log_mean)
    mcse = float(np.std(ratio, ddof=1) / np.sqrt(n_samples)) if n_samples > 1 else np.inf
    return float(total), mcse


def integrated_bic(log_evidence: float, n_params: int, n_obs: int) -> float:
    """Huys et al.'s integrated BIC, -2 log p(D | mu, sigma) + n_params log n_obs; lower is better.

    Parameters
    ----------
    log_evidence : float
        log p(D | mu, sigma), sampled (:func:`sampled_evidence`) or by Laplace.
    n_params : int
        The group's parameters: a mu and a sigma per fitted parameter (2k).
    n_obs : int
        The observations of all subjects.

    Returns
    -------
    float
        The iBIC.
    """
    return float(-2.0 * log_evidence + n_params * np.log(n_obs))
