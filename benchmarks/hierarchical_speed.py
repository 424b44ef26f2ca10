"""Speed of a hierarchical fit against per-subject maximum likelihood on many simulated subjects.

    python benchmarks/hierarchical_speed.py [--subjects 400] [--trials 250] [--starts 3] [--seed 0] [--workers 2]
        [--plain]

Every subject makes ``--trials`` choices on a two-armed bandit (reward probabilities 0.2 and 0.8) by
a delta rule with a softmax, perseveration and lapses (4 parameters):

    Q_c <- Q_c + alpha (r - Q_c) for the chosen arm c,
    P(choose 1) = lapse / 2 + (1 - lapse) expit(beta (Q_1 - Q_0) + kappa s), s = +1 / -1 / 0 if the
    previous choice was arm 1 / arm 0 / there was none,

with subjects drawn from a group on the unbounded scale (logit alpha ~ N(logit 0.3, 0.7^2),
logit(beta / 20) ~ N(logit 0.2, 0.5^2), kappa ~ N(0.5, 0.5^2), logit(lapse / 0.5) ~ N(logit 0.1, 0.7^2)).
The log-likelihood is numpy, vectorised over parameter sets (each arm's values follow a first-order
recursion: scipy's lfilter for each of a few sets, one in-place step per choice for many).

It prints the machine's load (1-minute average, against its cores), the wall time of
:func:`neurocur.fit.hierarchical.fit_hierarchical` (bounds alpha 0:1, beta 0:20, kappa unbounded,
lapse 0:0.5; SQUAREM, or plain EM with ``--plain``) and of :func:`neurocur.fit.mle.fit_ml` per
subject (kappa within -10:10, no intervals; BLAS on one thread, as the hierarchical fit runs itself),
both with the subjects in ``--workers`` processes (:class:`~neurocur.fit.workers.SubjectWorkers`),
the recovery (Pearson r and RMSE against the truth) of both, and the peak resident memory of this
process and of its largest worker (``resource.getrusage``). Times are wall and CPU (this process's
``time.process_time`` and its finished workers'; on a busy machine the CPU time is the fit's own
share). Targets: hierarchical <= 5 minutes, per-subject <= 60 s on 2 cores, memory <= 2 GB.
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numpy as np
from scipy import signal, special, stats
from threadpoolctl import threadpool_limits

from neurocur.fit.hierarchical import Subject, fit_hierarchical
from neurocur.fit.mle import fit_ml
from neurocur.fit.workers import SubjectWorkers

KEYS = ["alpha", "beta", "kappa", "lapse"]
P_REWARD = np.array([0.2, 0.8])
#: up to this many parameter sets, the values are filtered set by set
FEW = 32


def simulate(theta, n_trials: int, rng) -> tuple[np.ndarray, np.ndarray]:
    alpha, beta, kappa, lapse = theta
    q, prev = np.zeros(2), -1
    choices, rewards = np.zeros(n_trials, dtype=np.int64), np.zeros(n_trials)
    for t in range(n_trials):
        s = 0.0 if prev < 0 else 2.0 * prev - 1.0
        p1 = lapse / 2 + (1 - lapse) * special.expit(beta * (q[1] - q[0]) + kappa * s)
        c = int(rng.random() < p1)
        r = float(rng.random() < P_REWARD[c])
        q[c] += alpha * (r - q[c])
        choices[t], rewards[t], prev = c, r, c
    return choices, rewards


class Bandit:
    """One subject's log-likelihood for an (m, 4) array of parameter sets."""

    def __init__(self, choices: np.ndarray, rewards: np.ndarray):
        self.sign = np.where(choices == 1, 1.0, -1.0)
        self.stick = np.concatenate([[0.0], self.sign[:-1]])  # +1 / -1 after arm 1 / arm 0, 0 first
        self.rewards = [rewards[choices == a] for a in (0, 1)]
        # Q of arm a before trial t is its value after this many of its own updates
        self.updates = [np.concatenate([[0], np.cumsum(choices == a)[:-1]]) for a in (0, 1)]

    def __call__(self, params: np.ndarray) -> np.ndarray:
        alpha, beta, kappa, lapse = params.T
        q = [values(r, alpha) for r in self.rewards]
        diff = q[1][self.updates[1]] - q[0][self.updates[0]]
        z = self.sign[:, None] * (beta * diff + kappa * self.stick[:, None])
        with np.errstate(divide="ignore"):
            ll = np.logaddexp(np.log(lapse / 2), np.log1p(-lapse) + special.log_expit(z))
        return ll.sum(axis=0)


def values(r: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """An arm's values before and after each of its updates (len(r) + 1, m), Q_0 = 0,
    Q_{n+1} = (1 - alpha) Q_n + alpha r_n: scipy's lfilter per set for a few sets, else one
    in-place step per update for all sets at once."""
    out = np.zeros((len(r) + 1, len(alpha)))
    if len(alpha) <= FEW:
        for j, a in enumerate(alpha):
            out[1:, j] = signal.lfilter([a], [1.0, a - 1.0], r)
        return out
    keep, drive = 1.0 - alpha, r[:, None] * alpha[None, :]
    for n in range(len(r)):
        np.multiply(out[n], keep, out=out[n + 1])
        out[n + 1] += drive[n]
    return out


def group(n: int, rng) -> np.ndarray:
    x = rng.normal([special.logit(0.3), special.logit(0.2), 0.5, special.logit(0.1)], [0.7, 0.5, 0.5, 0.7], (n, 4))
    return np.column_stack([special.expit(x[:, 0]), 20 * special.expit(x[:, 1]), x[:, 2], 0.5 * special.expit(x[:, 3])])


def recovery(estimates: np.ndarray, truth: np.ndarray) -> str:
    r = [stats.pearsonr(estimates[:, j], truth[:, j])[0] for j in range(truth.shape[1])]
    rmse = np.sqrt(np.mean((estimates - truth) ** 2, axis=0))
    return ", ".join(f"{k} r={a:.2f} RMSE={b:.3g}" for k, a, b in zip(KEYS, r, rmse))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subjects", type=int, default=400)
    parser.add_argument("--trials", type=int, default=250)
    parser.add_argument("--starts", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--plain", action="store_true", help="plain EM (no SQUAREM)")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {args.workers} workers")
    rng = np.random.default_rng(args.seed)
    truth = group(args.subjects, rng)
    subjects = [Subject(Bandit(*simulate(theta, args.trials, rng)), args.trials, KEYS, vectorised=True)
                for theta in truth]
    print(f"{args.subjects} subjects x {args.trials} choices, 4 parameters")

    bounds = {"alpha": (0.0, 1.0), "beta": (0.0, 20.0), "kappa": (-np.inf, np.inf), "lapse": (0.0, 0.5)}
    t, cpu = time.perf_counter(), cpu_time()
    fit = fit_hierarchical(subjects, bounds, seed=args.seed, starts=args.starts, workers=args.workers,
                           accelerate=not args.plain)
    wall, cpu = time.perf_counter() - t, cpu_time() - cpu
    print(f"hierarchical fit: {wall:.1f} s wall, {cpu:.1f} s CPU (target <= 300 s), {fit.iterations} E-steps, "
          f"converged {fit.converged}, {fit.n_samples} samples for the iBIC")
    print(fit.group.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    s = fit.summary()
    print(f"log evidence: sampled {s['log_evidence']:.2f} (MC se {s['log_evidence_mcse']:.2f}), "
          f"Laplace {s['log_evidence_laplace']:.2f}; iBIC {s['ibic']:.1f}")
    by_map = fit.subjects.pivot(index="dataset", columns="param", values="estimate").loc[
        [f"s{i}" for i in range(args.subjects)], KEYS].to_numpy()
    print("  MAP recovery:", recovery(by_map, truth))

    ml_bounds = dict(bounds, kappa=(-10.0, 10.0))
    t, cpu = time.perf_counter(), cpu_time()
    with threadpool_limits(limits=1, user_api="blas"), SubjectWorkers(
            lambda i, _: fit_ml(subjects[i], ml_bounds, starts=args.starts, seed=i, ci=None),
            len(subjects), args.workers) as pool:
        fits = pool.map((), [None] * len(subjects))
    wall, cpu = time.perf_counter() - t, cpu_time() - cpu
    print(f"per-subject ML fits: {wall:.1f} s wall, {cpu:.1f} s CPU (target <= 60 s)")
    print("  ML recovery: ", recovery(np.array([[f.estimate[k] for k in KEYS] for f in fits]), truth))
    peak, worker = (resource.getrusage(who).ru_maxrss / 1024 for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    print(f"peak resident memory: {peak:.0f} MB here, {worker:.0f} MB in the largest worker (target <= 2048 MB)")


def cpu_time() -> float:
    """CPU seconds of this process and of its finished workers."""
    here, workers = (resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return here.ru_utime + here.ru_stime + workers.ru_utime + workers.ru_stime


if __name__ == "__main__":
    main()
