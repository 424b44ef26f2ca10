"""Simulation-based inference (neural posterior estimation, the ``sbi`` package) for parameters without a tractable likelihood.

A parameter whose effect passes through the learning part (``HPC.threshold``, EC's learning
rate) or through a dynamical system integrated per theta (the FitzHugh-Nagumo LC,
:attr:`~neurocur.regions.lc_fhn.FHNLC.closed_form`) has no cached likelihood: its replay would
be a whole new simulation for every theta. Neural posterior estimation (Greenberg, Nonnenmacher
& Macke 2019; Tejero-Cantero et al. 2020, the ``sbi`` package) learns p(theta | x) from
simulations instead, with x a vector of summary statistics of the behaviour (:func:`summaries`).

The training simulations are an experiment: :func:`training_experiment` writes a file that
extends the experiment and sweeps the parameters over values drawn from the uniform prior, and
:func:`neurocur.experiments.run_experiment` runs it into a results folder (the local pool or a
Dask cluster; an interrupted training set resumes). :func:`train` reads the folder, and the
posterior is sampled at the observed data's summaries. :class:`SBIStudy` is what ``neurocur sbi``
runs: the training runs, held-out runs at prior draws with seeds of their own (a
simulation-based check: Talts et al. 2018), NPE, and the posterior of each data set.
Install with ``pip install neurocur[fit]``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import ConfigError, extra
from ..results.safeio import atomic_text, own_dir
from .data import Behaviour

__all__ = ["SBIStudy", "held_out_draws", "n_values", "posterior_table", "summaries", "train", "training_experiment",
           "training_set"]

#: the summary statistics before the per-context ones, in order (:func:`summaries`)
SUMMARY_NAMES = ("switch_rate", "switch_rate_first_half", "switch_rate_second_half", "mean_run_length_log",
                 "entropy_of_contexts")
#: the parts of a data set whose context shares :func:`summaries` gives (quarters of the episodes)
PARTS = 4


def _mean(a: np.ndarray) -> float:
    return float(a.mean()) if len(a) else 0.0


def _shares(c: np.ndarray, n_contexts: int) -> np.ndarray:
    return np.bincount(c, minlength=n_contexts) / len(c) if len(c) else np.zeros(n_contexts)


def summaries(behaviour: Behaviour, n_contexts: int) -> np.ndarray:
    """x of a data set, from its sequence of contexts alone: the share of decisions that leave the
    context (overall, first and second half), the log of the mean number of episodes per stay, the
    entropy of the share of episodes in each context (bits) (:data:`SUMMARY_NAMES`); then per context
    its share of the episodes, its share in each of the :data:`PARTS` quarters of the episodes (part
    by part: when the agent moves on from a context it has learned) and its mean stay length in
    episodes (0 if never visited): 5 + (2 + PARTS) * n_contexts numbers."""
    c = np.asarray(behaviour.contexts)
    moved = c[1:] != c[:-1]
    half = len(moved) // 2
    share = _shares(c, n_contexts)
    nz = share[share > 0]
    first = np.flatnonzero(np.r_[True, moved])  # the first episode of each stay
    stays = np.bincount(c[first], minlength=n_contexts)
    length = np.bincount(c[first], weights=np.diff(np.r_[first, len(c)]), minlength=n_contexts)
    parts = [_shares(part, n_contexts) for part in np.array_split(c, PARTS)]
    return np.concatenate([[_mean(moved), _mean(moved[:half]), _mean(moved[half:]), np.log(len(c) / len(first)),
                            -(nz * np.log2(nz)).sum()], share, *parts, length / np.maximum(stays, 1)])


def _experiment_file(path: Path, experiment_path, name: str, values: Mapping[str, Sequence[float]], *, runs: int,
                     steps: int, seed: int) -> Path:
    """Write (whole) an experiment file that extends ``experiment_path`` and sweeps ``values``."""
    lines = [f"extends = {str(Path(experiment_path).resolve())!r}", f"name = {name!r}", f"runs = {int(runs)}",
             f"steps = {int(steps)}", f"seed = {int(seed)}", "", "[sweep]"]
    lines += [f'"{key}" = [{", ".join(repr(float(v)) for v in vs)}]' for key, vs in values.items()]
    atomic_text(path, "\n".join(lines) + "\n")
    return path


def _check(prior: Mapping[str, tuple[float, float]]) -> None:
    for key, (low, high) in prior.items():
        if not low < high:
            raise ConfigError("prior", key, "LOW < HIGH", f"{low}:{high}")


def training_experiment(experiment_path, prior: Mapping[str, tuple[float, float]], *, n_values: int, runs: int,
                        steps: int, seed: int, out) -> Path:
    """Write ``OUT/sbi_training.toml``: the experiment (extended), swept over ``n_values`` values of
    each prior parameter drawn uniformly (seeded), ``runs`` runs per point of ``steps`` frames.
    With several parameters the points are the product of their values. Every condition of the
    file is swept; run the one to fit (``run_experiment(..., conditions=[name])``). Run *i* of
    every point has the same seed (paired), so the runs give the posterior ``runs`` draws of the
    model's noise at every theta."""
    _check(prior)
    rng = np.random.default_rng(seed)
    values = {key: np.sort(rng.uniform(low, high, n_values)) for key, (low, high) in prior.items()}
    Path(out).mkdir(parents=True, exist_ok=True)
    return _experiment_file(own_dir(Path(out)) / "sbi_training.toml", experiment_path, "sbi_training", values,
                            runs=runs, steps=steps, seed=seed)


def held_out_draws(prior: Mapping[str, tuple[float, float]], n: int, seed: int) -> list[tuple[int, dict[str, float]]]:
    """``n`` held-out simulations: each (its experiment seed, theta drawn uniformly from the prior),
    from streams of their own (``SeedSequence([seed, 1])``), so none shares a training run's seed."""
    _check(prior)
    b = np.array(list(prior.values()), dtype=np.float64)
    theta = np.random.default_rng(np.random.SeedSequence([seed, 1])).uniform(b[:, 0], b[:, 1], (n, len(prior)))
    seeds = np.random.SeedSequence([seed, 2]).generate_state(n, np.uint64) >> np.uint64(1)
    return [(int(s), dict(zip(prior, map(float, t)))) for s, t in zip(seeds, theta)]


def training_set(results, prior: Mapping[str, tuple[float, float]], n_contexts: int) -> tuple[np.ndarray, np.ndarray]:
    """(theta, x) of every run of a training results folder: the swept values and the summaries."""
    from ..results import ResultsStore

    episodes, _ = ResultsStore(results).load()
    keys = list(prior)
    missing = [k for k in keys if k not in episodes]
    if missing:
        raise ConfigError(results, missing[0], "a swept column of the training runs", "none")
    theta, x = [], []
    for _, run in episodes.groupby(["condition", "run"], sort=True):
        b = Behaviour("run", run["context"].to_numpy(), np.zeros(len(run), np.int64), {}, str(results))
        theta.append(run[keys].iloc[0].to_numpy(dtype=np.float64))
        x.append(summaries(b, n_contexts))
    return np.array(theta), np.array(x)


class _Silent:
    """An sbi tracker that keeps nothing: sbi's default writes TensorBoard logs into the working folder,
    and nothing is written outside a results folder."""

    log_dir = None

    def log_metric(self, name, value, step=None) -> None:
        pass

    def log_metrics(self, metrics, step=None) -> None:
        pass

    def log_params(self, params) -> None:
        pass

    def add_figure(self, name, figure, step=None) -> None:
        pass

    def flush(self) -> None:
        pass


def train(theta: np.ndarray, x: np.ndarray, prior: Mapping[str, tuple[float, float]], *, seed: int = 0,
          max_epochs: int = 200):
    """A neural posterior estimator (sbi's NPE, a masked autoregressive flow) trained on (theta, x);
    returns a function ``sample(x_observed, n) -> (n, len(prior)) array``."""
    with extra("fit", "simulation-based inference"):
        import torch
        from sbi.inference import NPE
        from sbi.utils import BoxUniform

    torch.manual_seed(seed)
    b = np.array(list(prior.values()), dtype=np.float32)
    box = BoxUniform(torch.tensor(b[:, 0]), torch.tensor(b[:, 1]))
    inference = NPE(prior=box, show_progress_bars=False, tracker=_Silent())
    inference.append_simulations(torch.tensor(theta, dtype=torch.float32), torch.tensor(x, dtype=torch.float32))
    inference.train(max_num_epochs=max_epochs, show_train_summary=False, training_batch_size=min(50, len(theta)))
    posterior = inference.build_posterior()

    def sample(x_observed: Sequence[float], n: int = 1000) -> np.ndarray:
        torch.manual_seed(seed)
        s = posterior.sample((n,), x=torch.tensor(np.asarray(x_observed, dtype=np.float32)), show_progress_bars=False)
        return s.numpy().astype(np.float64)

    return sample


def posterior_table(samples: np.ndarray, prior: Mapping[str, tuple[float, float]], dataset: str) -> pd.DataFrame:
    """``dataset, param, estimate, ci_low, ci_high``: posterior median and central 95 % interval."""
    return pd.DataFrame([{"dataset": dataset, "param": k, "estimate": float(np.median(samples[:, i])),
                          "ci_low": float(np.quantile(samples[:, i], 0.025)),
                          "ci_high": float(np.quantile(samples[:, i], 0.975))} for i, k in enumerate(prior)])


def n_values(prior: Mapping[str, tuple[float, float]], simulations: int, runs: int) -> int:
    """The prior draws of each parameter that make ``simulations`` training runs of ``runs`` runs per
    point (their product over the parameters, times ``runs``); a one-line error when there is none."""
    k = len(prior)
    if runs < 1:
        raise ConfigError("--runs", None, "an integer >= 1", str(runs))
    n = max(2, round((simulations / runs) ** (1 / k)))
    if n**k * runs != simulations:
        raise ConfigError("--simulations", None, f"RUNS x DRAWS^{k} with at least 2 draws (--runs {runs}, "
                          f"{k} prior parameter(s): e.g. {n**k * runs})", str(simulations))
    return n


@dataclass
class SBIStudy:
    """NPE of ``condition``'s ``prior`` parameters (what ``neurocur sbi`` runs) inside the folder ``out``:
    the training runs (``out/sbi_training.toml`` into ``out/runs/``) and the held-out runs
    (``out/sbi_test/tNN.toml`` into ``out/sbi_test/tNN/``, one run each with its own seed) are
    experiments computed by ``executor`` (:func:`~neurocur.experiments.executors.executor_for`), so an
    interrupted study resumes, run by run (a run is short next to the set: no checkpoints within a
    run). torch is imported only by :meth:`fit`, after the runs."""

    experiment: object
    condition: str
    prior: dict
    out: Path
    steps: int
    seed: int = 0

    def simulate(self, executor, *, simulations: int, runs: int, tests: int = 0) -> None:
        """Compute (or resume) the training runs and ``tests`` held-out runs."""
        if tests < 0:
            raise ConfigError("--test", None, "an integer >= 0", str(tests))
        from ..experiments import load_experiment, run_experiment

        path = training_experiment(self.experiment.path, self.prior, n_values=n_values(self.prior, simulations, runs),
                                   runs=runs, steps=self.steps, seed=self.seed, out=self.out)
        run_experiment(load_experiment(path), own_dir(self.out, "runs"), conditions=[self.condition], executor=executor,
                       checkpoint_every=0)
        for i, (seed, theta) in enumerate(held_out_draws(self.prior, tests, self.seed)):
            path = _experiment_file(own_dir(self.out, "sbi_test") / f"t{i:02d}.toml", self.experiment.path, "sbi_test",
                                    {k: [v] for k, v in theta.items()}, runs=1, steps=self.steps, seed=seed)
            run_experiment(load_experiment(path), own_dir(self.out, "sbi_test", f"t{i:02d}"),
                           conditions=[self.condition], executor=executor, checkpoint_every=0)

    def fit(self, n_contexts: int, *, epochs: int = 200):
        """The posterior sampler trained on the training runs (:func:`train`)."""
        theta, x = training_set(self.out / "runs", self.prior, n_contexts)
        return train(theta, x, self.prior, seed=self.seed, max_epochs=epochs)

    def recovery(self, sample, n_contexts: int, tests: int, n: int = 2000) -> pd.DataFrame:
        """``dataset, param, true, estimate, ci_low, ci_high`` of the held-out runs (posterior median
        and central 95 % interval of ``n`` samples at each run's summaries)."""
        tables = []
        for i in range(tests):
            theta, x = training_set(self.out / "sbi_test" / f"t{i:02d}", self.prior, n_contexts)
            table = posterior_table(sample(x[0], n), self.prior, f"t{i:02d}")
            tables.append(table.assign(true=theta[0]))
        columns = ["dataset", "param", "true", "estimate", "ci_low", "ci_high"]
        return pd.concat(tables, ignore_index=True)[columns] if tables else pd.DataFrame(columns=columns)

    def posterior(self, sample, datasets: Sequence[Behaviour], n_contexts: int, n: int = 2000) -> pd.DataFrame:
        """:func:`posterior_table` of every data set."""
        return pd.concat([posterior_table(sample(summaries(b, n_contexts), n), self.prior, b.name) for b in datasets],
                         ignore_index=True)
