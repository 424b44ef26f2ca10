"""EM's iteration for a hierarchical fit (:mod:`neurocur.fit.hierarchical`): plain, or accelerated by SQUAREM.

Plain EM maps the group prior p = (mu, log sigma) to F(p): an E-step under p (each subject's MAP and
Laplace covariance), then the M-step. It converges linearly, slowly where a parameter's missing
information is large. SQUAREM (Varadhan & Roland 2008, Scand J Stat 35:335, scheme S3) takes two EM
steps p0 -> p1 -> p2, r = p1 - p0, v = p2 - 2 p1 + p0, and goes to p0 + 2 a r + a^2 v with
a = |r| / |v| within [1, step_max] (a = 1 is p2, plain EM); step_max grows fourfold after a step at it
and shrinks back when the point it gave has no E-step (a subject without a maximum there: a
ConfigError), which is then p2's. No objective guards the step (the Laplace evidence is not EM's
objective). EM stops only on a plain EM step, when the Laplace log evidence changes by less than its
tolerance or no mu or sigma moves by more than its own: acceleration changes the path, not the fixed
point.
"""

from __future__ import annotations

import numpy as np

from ..config import ConfigError

__all__ = ["iterate"]


def iterate(e_step, history: list, first: tuple, floor: float, max_iter: int, tol: tuple[float, float],
            accelerate: bool):
    """EM from a first group prior, plain or by SQUAREM (module docstring).

    Parameters
    ----------
    e_step : callable
        ``e_step(mu, var, warm MAPs)`` returns (mu, var, MAPs, covariances, Laplace log evidences) and
        appends the evidences' sum to ``history``.
    history : list
        The Laplace log evidence of each E-step, appended to by ``e_step``.
    first : tuple
        The first prior (mu, var).
    floor : float
        The smallest variance of the M-step.
    max_iter : int
        The most E-steps.
    tol : tuple of float
        The stop rule's tolerances: on the change of the summed Laplace log evidence over a plain EM step,
        and on the largest move of a mu or a sigma.
    accelerate : bool
        SQUAREM's steps between the plain ones.

    Returns
    -------
    tuple
        The last E-step's five, ``history`` and whether EM converged (stopped before ``max_iter``).
    """
    tol_evidence, tol_move = tol
    k = len(first[0])
    here = e_step(*first, None)
    step_max = 1.0
    while len(history) < max_iter:
        mu, var, maps, covs, evidence = here
        after = e_step(*_m_step(maps, covs, floor), maps)
        moved = max(np.max(np.abs(after[0] - mu)), np.max(np.abs(np.sqrt(after[1]) - np.sqrt(var))))
        if abs(history[-1] - history[-2]) < tol_evidence or moved < tol_move:
            return (*after, history, True)
        if not accelerate or len(history) == max_iter:
            here = after
            continue
        # SQUAREM's step (module docstring)
        p0, p1 = _packed(mu, var), _packed(after[0], after[1])
        p2 = _packed(*_m_step(after[2], after[3], floor))
        r, v = p1 - p0, p2 - 2 * p1 + p0
        a = float(np.clip(np.sqrt(r @ r / (v @ v)) if v @ v > 0 else step_max, 1.0, step_max))
        here = None
        if a > 1.0:
            try:
                here = e_step(*_unpacked(p0 + 2 * a * r + a**2 * v, k, floor), after[2])
            except ConfigError:
                step_max = max(1.0, step_max / 4) if a == step_max else step_max
        if here is None:
            here = e_step(*_unpacked(p2, k, floor), after[2]) if len(history) < max_iter else after
        if a == step_max:
            step_max *= 4
    return (*here, history, False)


def _m_step(maps: np.ndarray, covs: np.ndarray, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """mu = mean_i m_i, var = mean_i ((m_i - mu)^2 + diag V_i), at least ``floor``."""
    mu = maps.mean(axis=0)
    return mu, np.maximum(np.mean((maps - mu) ** 2 + np.diagonal(covs, axis1=1, axis2=2), axis=0), floor)


def _packed(mu: np.ndarray, var: np.ndarray) -> np.ndarray:
    return np.concatenate([mu, 0.5 * np.log(var)])


def _unpacked(p: np.ndarray, k: int, floor: float) -> tuple[np.ndarray, np.ndarray]:
    return p[:k], np.maximum(np.exp(2 * p[k:]), floor)
