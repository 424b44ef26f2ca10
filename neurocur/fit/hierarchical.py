"""Hierarchical fits: group parameters by empirical-Bayes EM with a Laplace approximation (Huys et al. 2011).

Huys, Cools, Gölzer, Friedel, Heinz, Dolan & Dayan (2011), PLoS Comput Biol 7:e1002028, methods
("emfit"). Subject i's parameters x_i, on the unbounded scale of :mod:`neurocur.fit.transforms`
(logit for two bounds, log for one, identity for none), are drawn from a group prior
N(mu, diag(sigma^2)); theta_i = T(x_i) is what the subject's log-likelihood log L_i takes.

- **E-step** (under the current mu, sigma): the MAP m_i maximises
  log L_i(T(x)) + log N(x; mu, sigma^2), and the Laplace posterior covariance V_i is the inverse of
  the negative log-posterior's Hessian at m_i (:func:`~neurocur.fit.evidence.posterior_mode`).
  Starts: in the first E-step the ``starts`` best of
  the prior mean and a seeded 64-point scrambled Sobol design mapped through the prior's quantiles
  (mu + sigma Phi^-1(u), as :func:`~neurocur.fit.mle.fit_ml` chooses its starts); later E-steps
  start from the previous MAP (warm start) and from the design points, mapped through the new
  prior, whose log-posterior already beats it (at most ``starts - 1``).
- **M-step**: mu = mean_i m_i, sigma^2 = mean_i ((m_i - mu)^2 + diag V_i) (at least :data:`VAR_FLOOR`).
- The first prior is mu = 0 (the midpoint of two bounds, one above a single bound), sigma =
  :data:`INIT_SD`. EM stops when, over one plain EM step (an E-step, the M-step, and the E-step
  under the new prior), the Laplace log marginal likelihood changes by less than ``tol`` per subject
  (``tol`` times the subjects) or no mu or sigma moves by more than ``tol``; or after ``max_iter``
  E-steps. The tolerance is per subject because the Laplace evidence is a sum of per-subject terms,
  each from a numerical MAP and Hessian (L-BFGS-B, central differences), and because EM with a
  Laplace E-step is not exact EM: where a parameter is weakly identified its plain steps can creep
  along a ridge and *lower* the Laplace evidence by a roughly constant amount per subject. On the
  400-subject bandit of ``benchmarks/hierarchical_speed.py`` the lapse rate's mu fell from -2.4 to
  -3.6 and its sigma from 0.68 to 0.30 (logit scale) between E-steps 7 and 93, while most plain
  steps changed the summed evidence by -0.4 to -0.008 (1e-3 to 2e-5 per subject; a few by up to +4
  after a SQUAREM jump) and the evidence fell from -32858 to -32905: an absolute 1e-4 on that sum
  was not met within the 200-step cap.
  Huys & Schad's emfit stops on the change of the summed log posterior, 1e-3 absolute, at most 500
  iterations (mpc-ucl/emfit, ``lib/emfit.m``); Piray's HBI when the root mean square change of the
  group means in units of their sds is below 0.01, at most 50 iterations (payampiray/cbm,
  ``codes/cbm_hbi_config.m``). The default here, 1e-3 per subject, is emfit's for one subject. The
  last E-step is under the reported mu, sigma, so the subjects' table is the reported prior's.
- **Acceleration** (``accelerate``, the default): EM converges linearly, slowly where a parameter's
  missing information is large (a weakly identified lapse rate took more than 200 E-steps on 400
  subjects). SQUAREM (Varadhan & Roland 2008, Scand J Stat 35:335, scheme S3) extrapolates the
  fixed-point map along two EM steps on (mu, log sigma) (:mod:`neurocur.fit.squarem`); it changes
  EM's path, not its fixed point, since EM stops only on a plain step. Each subject's MAP starts from its previous one.

**Evidence** (:mod:`neurocur.fit.evidence`). log p(D | mu, sigma) = sum_i log integral L_i(T(x))
N(x; mu, sigma^2) dx, two ways: by Laplace, the sum of the subjects' Laplace log evidences at their
MAPs (``subject_log_evidence``, what ``neurocur compare --hierarchical`` gives random-effects BMS), and
by sampling ``n_samples`` draws of the group prior, as Huys et al. do. The integrated BIC (Huys et al.'s
iBIC) is iBIC = -2 log p(D | mu, sigma) + 2k log N, with k fitted parameters (a mu and a sigma each) and
N the total number of observations; lower is better.

**Group table** (on each parameter's own scale): ``mean`` and ``sd`` of T(x), x ~ N(mu, sigma^2),
by 61-point Gauss–Hermite quadrature; ``ci_low, ci_high``: that mean at mu -/+ z se(mu), sigma
held at its estimate, with se(mu) from the observed information of the marginal likelihood
for mu by Louis' (1982) missing-information identity under the Laplace posteriors,
I(mu) = N diag(1/sigma^2) - diag(1/sigma^2) (sum_i V_i) diag(1/sigma^2) (exact for Gaussian
subjects; never below the sqrt(sigma^2/N) of the subjects' spread alone). **Subjects' table**:
T(m_i) and T(m_i -/+ z sqrt(V_i,kk)), the Laplace posterior's central interval mapped to the own scale.

The EM runs with BLAS limited to one thread: scipy's L-BFGS-B (since 1.15) makes many tiny BLAS
calls, each of which costs milliseconds with OpenBLAS's threads on a busy machine.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import special, stats
from threadpoolctl import threadpool_limits

from ..config import ConfigError
from ..config.checks import check_positive_int
from .evidence import checked_loglik, integrated_bic, posterior_mode, sampled_evidence
from .mle import DESIGN
from .squarem import iterate
from .transforms import Transforms
from .workers import SubjectWorkers

__all__ = ["HierarchicalFit", "Subject", "fit_hierarchical"]

#: the first group prior's sigma on every unbounded scale
INIT_SD = 3.0
#: the smallest group variance the M-step returns
VAR_FLOOR = 1e-6
#: Gauss–Hermite nodes for the population's mean and sd on the own scale
NODES = 61
#: the most E-steps by default (``max_iter``; ``--em-iterations``)
MAX_ITER = 200
#: the stop rule's tolerance by default (``tol``): per subject on the Laplace log evidence, absolute on mu and sigma
TOL = 1e-3
#: draws from the group prior for the sampled evidence by default (``n_samples``; ``--evidence-samples``)
N_SAMPLES = 2000


@dataclass
class HierarchicalFit:
    """A hierarchical fit: group ``mu``, ``sigma``, ``mu_se`` on the unbounded scale, the ``subjects``
    (``dataset, param, estimate, ci_low, ci_high``) and ``group`` (``param, mean, sd, ci_low, ci_high,
    kind, mu, sigma, mu_se``) tables, log p(D | mu, sigma) sampled (``log_evidence``, with its Monte
    Carlo ``log_evidence_mcse`` over ``n_samples``) and by Laplace, the EM's ``history`` (the
    Laplace log evidence per E-step), and each subject's term of the Laplace evidence under the reported
    prior (``subject_log_evidence``, in the subjects' order; their log-likelihoods for a model without
    free parameters).

    Parameters
    ----------
    keys : list
        The fitted parameters, in the order of ``mu`` and ``sigma``.
    n_subjects : int
        The subjects.
    mu : numpy.ndarray
        The group means on the unbounded scale.
    sigma : numpy.ndarray
        The group sds on the unbounded scale.
    mu_se : numpy.ndarray
        The standard errors of ``mu`` (Louis' identity).
    subjects : pandas.DataFrame
        ``dataset, param, estimate, ci_low, ci_high``: each subject's MAP and Laplace interval.
    group : pandas.DataFrame
        ``param, mean, sd, ci_low, ci_high, kind, mu, sigma, mu_se``: the population on each own scale.
    log_evidence : float
        log p(D | mu, sigma) by sampling the group prior.
    log_evidence_mcse : float
        Its Monte Carlo standard error.
    log_evidence_laplace : float
        log p(D | mu, sigma) by Laplace at the MAPs.
    n_obs : int
        The observations of all subjects.
    n_samples : int
        Draws from the group prior for ``log_evidence``.
    iterations : int
        The E-steps EM made.
    converged : bool
        Whether EM met its stop rule before ``max_iter`` E-steps.
    history : list
        The Laplace log evidence after each E-step.
    subject_log_evidence : numpy.ndarray
        Each subject's Laplace log evidence under the reported prior.
    """

    keys: list
    n_subjects: int
    mu: np.ndarray
    sigma: np.ndarray
    mu_se: np.ndarray
    subjects: pd.DataFrame
    group: pd.DataFrame
    log_evidence: float
    log_evidence_mcse: float
    log_evidence_laplace: float
    n_obs: int
    n_samples: int
    iterations: int
    converged: bool
    history: list
    subject_log_evidence: np.ndarray

    @property
    def n_params(self) -> int:
        """Group parameters: a mu and a sigma per fitted parameter."""
        return 2 * len(self.keys)

    @property
    def ibic(self) -> float:
        return integrated_bic(self.log_evidence, self.n_params, self.n_obs)

    @property
    def ibic_laplace(self) -> float:
        return integrated_bic(self.log_evidence_laplace, self.n_params, self.n_obs)

    def summary(self) -> dict:
        return {"n_subjects": self.n_subjects, "n_params": self.n_params, "n_obs": self.n_obs, "log_evidence": self.log_evidence,
                "log_evidence_mcse": self.log_evidence_mcse, "n_samples": self.n_samples,
                "log_evidence_laplace": self.log_evidence_laplace, "ibic": self.ibic,
                "ibic_laplace": self.ibic_laplace, "iterations": self.iterations, "converged": self.converged}


class Subject:
    """A subject's log-likelihood offered as a replay offers it (``loglik(theta or thetas)``, ``n_obs``), so
    that :func:`fit_hierarchical` and :func:`~neurocur.fit.mle.fit_ml` take the same subjects.
    ``fn`` maps a parameter vector on the own scale (shape (k,), in ``keys``' order) to a log-likelihood;
    with ``vectorised``, an (m, k) array to m of them.

    Parameters
    ----------
    fn : callable
        The log-likelihood of a parameter vector (or, with ``vectorised``, of the rows of an (m, k) array).
    n_obs : int
        The subject's observations.
    keys : sequence of str
        The parameters, in the order ``fn`` takes them.
    vectorised : bool
        ``fn`` takes an (m, k) array and returns m log-likelihoods.
    """

    def __init__(self, fn, n_obs: int, keys: Sequence[str], *, vectorised: bool = False):
        self.fn, self.keys, self.vectorised = fn, list(keys), vectorised
        self.n_obs = check_positive_int(n_obs, "n_obs")

    def evaluate(self, points) -> np.ndarray:
        """The log-likelihoods of the rows of ``points`` (m, k)."""
        points = np.atleast_2d(np.asarray(points, dtype=np.float64))
        if self.vectorised:
            return np.asarray(self.fn(points), dtype=np.float64).reshape(len(points))
        return np.array([float(self.fn(p)) for p in points])

    def loglik(self, theta, mask=None):
        if mask is not None:
            raise ConfigError("mask", None, "no mask (a Subject scores all its observations)", "a mask")
        thetas = [theta] if isinstance(theta, Mapping) else list(theta)
        out = self.evaluate([[t[k] for k in self.keys] for t in thetas])
        return float(out[0]) if isinstance(theta, Mapping) else out


def _evaluator(subject, keys: list):
    """(m, k) own-scale points -> m log-likelihoods, for a :class:`Subject` or a replay."""
    if isinstance(subject, Subject) and subject.keys == keys:
        return subject.evaluate
    return lambda points: np.asarray(subject.loglik([dict(zip(keys, map(float, p))) for p in points]),
                                     dtype=np.float64).reshape(len(points))


def fit_hierarchical(subjects, bounds: Mapping[str, tuple[float, float]], *, n_obs: Sequence[int] | None = None,
                     vectorised: bool = False, names: Sequence[str] | None = None, seed: int = 0, starts: int = 3,
                     max_iter: int = MAX_ITER, tol: float = TOL, n_samples: int = N_SAMPLES,
                     level: float = 0.95, accelerate: bool = True, workers: int = 1) -> HierarchicalFit:
    """Group and per-subject parameters of ``subjects`` by empirical-Bayes EM (module docstring).

    Parameters
    ----------
    subjects : sequence
        Each a replay (or a :class:`Subject`: anything with ``loglik(list of {key: value})`` and ``n_obs``, as
        :func:`~neurocur.fit.mle.fit_ml` takes) or a callable of the own-scale vector (k,) in ``bounds``' order.
    bounds : mapping of str to (float, float)
        ``{key: (low, high)}``, -inf/inf for none; none at all evaluates a model without free parameters.
    n_obs : sequence of int, optional
        Each callable subject's number of observations.
    vectorised : bool
        The callables take an (m, k) array of points.
    names : sequence of str, optional
        The subjects' names in the tables (default ``s0``, ``s1``, ...).
    seed : int
        The Sobol design's and the evidence samples' seed.
    starts : int
        Local searches of each subject's first E-step.
    max_iter : int
        The most E-steps.
    tol : float
        The stop rule's tolerance: per subject on the Laplace log evidence, absolute on mu and sigma.
    n_samples : int
        Draws from the group prior for the sampled evidence and the iBIC.
    level : float
        The intervals' level.
    accelerate : bool
        SQUAREM on the EM (else plain EM).
    workers : int
        Processes for the subjects' MAPs (the same fit for any number, :mod:`neurocur.fit.workers`).

    Returns
    -------
    HierarchicalFit
        The group's and the subjects' tables, the evidences, the iBIC and the EM's history.
    """
    transforms = Transforms(bounds)
    keys = transforms.keys
    subjects = list(subjects)
    if not subjects:
        raise ConfigError("subjects", None, "at least one subject", "none")
    names = [f"s{i}" for i in range(len(subjects))] if names is None else [str(n) for n in names]
    for key, values in (("names", names), ("n_obs", n_obs)):
        if values is not None and len(values) != len(subjects):
            raise ConfigError("subjects", key, f"one per subject ({len(subjects)})", str(len(values)))
    for i, s in enumerate(subjects):
        if not (hasattr(s, "loglik") and hasattr(s, "n_obs")):
            if not callable(s) or n_obs is None:
                raise ConfigError("subjects", names[i], "a replay, a Subject, or a callable with n_obs given",
                                  type(s).__name__)
            subjects[i] = Subject(s, n_obs[i], keys, vectorised=vectorised)
    starts, max_iter, n_samples = (check_positive_int(v, k) for v, k in
                                   ((starts, "starts"), (max_iter, "max_iter"), (n_samples, "n_samples")))
    if not 0 < level < 1:
        raise ConfigError("<python>", "level", "an interval's level in (0, 1)", repr(level))
    if not tol > 0:
        raise ConfigError("<python>", "tol", "a tolerance > 0", repr(tol))
    total = int(sum(s.n_obs for s in subjects))
    fns = [_evaluator(s, keys) for s in subjects]
    k = len(keys)
    if k == 0:
        each = np.array([checked_loglik(f, np.zeros((1, 0)), n)[0] for f, n in zip(fns, names)])
        ll = float(each.sum())
        empty = pd.DataFrame(columns=["dataset", "param", "estimate", "ci_low", "ci_high"])
        return HierarchicalFit([], len(subjects), np.zeros(0), np.zeros(0), np.zeros(0), empty, _group_table(
            transforms, np.zeros(0), np.zeros(0), np.zeros(0), 0.0), ll, 0.0, ll, total, 0, 0, True, [], each)

    design_seed, sample_seed = np.random.SeedSequence(seed).spawn(2)
    with threadpool_limits(limits=1, user_api="blas"):  # scipy's L-BFGS-B: many tiny BLAS calls
        mu, var, maps, covs, evidence, history, converged = _em(fns, transforms, names, design_seed, starts, max_iter, tol,
                                                                     accelerate, workers)
    mu_se = _mu_se(var, covs)
    z = float(special.ndtri(0.5 + level / 2))
    sd = np.sqrt(np.diagonal(covs, axis1=1, axis2=2))
    rows = []
    for i, name in enumerate(names):
        est, lo, hi = (transforms.to_own(maps[i] + d * z * sd[i]) for d in (0.0, -1.0, 1.0))
        rows += [{"dataset": name, "param": key, "estimate": float(est[j]), "ci_low": float(lo[j]),
                  "ci_high": float(hi[j])} for j, key in enumerate(keys)]
    log_ev, mcse = sampled_evidence(fns, transforms, mu, var, n_samples, sample_seed, names)
    return HierarchicalFit(keys, len(subjects), mu, np.sqrt(var), mu_se, pd.DataFrame(rows),
                           _group_table(transforms, mu, np.sqrt(var), mu_se, z), log_ev, mcse, history[-1],
                           total, n_samples, len(history), converged, history, evidence)


def _em(fns, transforms: Transforms, names, seed, starts: int, max_iter: int, tol: float, accelerate: bool,
        workers: int):
    """The EM iterations (module docstring), accelerated by SQUAREM unless not ``accelerate``, each E-step's
    subjects in ``workers`` processes (:class:`~neurocur.fit.workers.SubjectWorkers`): the last E-step, under
    the returned mu, var, gives the MAPs, their covariances and the subjects' Laplace log evidences."""
    k = len(transforms)
    unit = stats.qmc.Sobol(k, rng=np.random.default_rng(seed)).random_base2(int(np.log2(DESIGN)))
    normal = special.ndtri(np.clip(unit, 1e-9, 1 - 1e-9))
    history: list[float] = []

    def mode(i, mu, var, design, warm):
        return posterior_mode(fns[i], transforms, mu, var, design, warm, starts, names[i])

    with SubjectWorkers(mode, len(fns), workers) as pool:
        def e_step(mu, var, warm):  # the MAPs, covariances and Laplace log evidences under N(mu, var)
            design = np.vstack([mu, mu + np.sqrt(var) * normal])
            results = pool.map((mu, var, design), [None] * len(fns) if warm is None else list(warm))
            step = (mu, var, np.array([r[0] for r in results]), np.array([r[1] for r in results]),
                    np.array([r[2] for r in results]))
            history.append(float(sum(step[4])))  # the same order of additions as before
            return step

        return iterate(e_step, history, (np.zeros(k), np.full(k, INIT_SD**2)), VAR_FLOOR, max_iter,
                       (tol * len(fns), tol), accelerate)


def _mu_se(var: np.ndarray, covs: np.ndarray) -> np.ndarray:
    """se(mu) from Louis' identity (module docstring); inf where the information is not positive definite."""
    d = np.diag(1.0 / var)
    info = len(covs) * d - d @ covs.sum(axis=0) @ d
    try:
        np.linalg.cholesky(info)
    except np.linalg.LinAlgError:
        return np.full(len(var), np.inf)
    return np.sqrt(np.diag(np.linalg.inv(info)))


def _group_table(transforms: Transforms, mu, sigma, mu_se, z: float) -> pd.DataFrame:
    """Per parameter the population's mean and sd on the own scale (Gauss–Hermite), the mean's interval."""
    nodes, weights = np.polynomial.hermite_e.hermegauss(NODES)
    weights = weights / weights.sum()

    def moments(m):  # mean and sd of T(m + sigma z), z ~ N(0, 1), per parameter
        values = transforms.to_own(m[None, :] + sigma[None, :] * nodes[:, None])
        mean = weights @ values
        return mean, np.sqrt(np.maximum(weights @ (values - mean) ** 2, 0.0))

    mean, sd = moments(mu)
    with np.errstate(invalid="ignore"):
        low, high = moments(mu - z * mu_se)[0], moments(mu + z * mu_se)[0]
    return pd.DataFrame({"param": transforms.keys, "mean": mean, "sd": sd, "ci_low": low, "ci_high": high,
                         "kind": transforms.kinds, "mu": mu, "sigma": sigma, "mu_se": mu_se},
                        columns=["param", "mean", "sd", "ci_low", "ci_high", "kind", "mu", "sigma", "mu_se"])
