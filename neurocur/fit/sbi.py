"""Simulation-based inference (neural posterior estimation, the ``sbi`` package) for parameters without a tractable likelihood.

A parameter whose effect passes through the learning part (``HPC.threshold``, EC's learning
rate) or through a dynamical system integrated per theta (the FitzHugh-Nagumo LC,
:attr:`~neurocur.regions.lc_fhn.FHNLC.closed_form`) has no cached likelihood: its replay would
be a whole new simulation for every theta. Neural posterior estimation (Greenberg, Nonnenmacher
& Macke 2019; Tejero-Cantero et al. 2020, the ``sbi`` package) learns p(theta | x) from
simulations instead, with x a vector of summary statistics of the behaviour (:func:`summaries`).

The training simulations are experiments: :func:`draw_experiments` writes one file per draw
from the uniform prior, which extends the experiment at that draw with a seed of its own, and
:func:`neurocur.experiments.run_experiment` runs each into a results folder (the local pool or a
Dask cluster; an interrupted training set resumes). :func:`train` learns from the folders'
runs, and the posterior is sampled at the observed data's summaries. :class:`SBIStudy` is what ``neurocur sbi``
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

__all__ = ["SBIStudy", "draw_experiments", "n_draws", "posterior_table", "prior_draws", "summaries", "train",
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
    episodes (0 if never visited): 5 + (2 + PARTS) * n_contexts numbers.

    Parameters
    ----------
    behaviour : Behaviour
        The data set.
    n_contexts : int
        The world's contexts.

    Returns
    -------
    array of shape (5 + (2 + PARTS) * n_contexts,)
        The summaries, in the order above.
    """
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


def _check(prior: Mapping[str, tuple[float, float]]) -> None:
    for key, (low, high) in prior.items():
        if not low < high:
            raise ConfigError("prior", key, "LOW < HIGH", f"{low}:{high}")


def prior_draws(prior: Mapping[str, tuple[float, float]], n: int, root: np.random.SeedSequence
                ) -> list[tuple[int, dict[str, float]]]:
    """``n`` draws from the uniform prior, each with an experiment seed of its own: ``(seed, theta)``.
    theta and the seeds come from two children of ``root``.

    Parameters
    ----------
    prior : mapping of str to (float, float)
        The uniform prior: each inferred key's bounds.
    n : int
        The draws.
    root : numpy.random.SeedSequence
        The root of the draws and their seeds.

    Returns
    -------
    list of (int, dict of str to float)
        ``(seed, theta)`` of each draw.
    """
    _check(prior)
    b = np.array(list(prior.values()), dtype=np.float64)
    thetas, seeds = root.spawn(2)
    theta = np.random.default_rng(thetas).uniform(b[:, 0], b[:, 1], (n, len(prior)))
    return [(int(s), dict(zip(prior, map(float, t))))
            for s, t in zip(seeds.generate_state(n, np.uint64) >> np.uint64(1), theta)]


def draw_experiments(experiment_path, prior: Mapping[str, tuple[float, float]], *, n: int, runs: int, steps: int,
                     seed: int, out, held_out: bool = False) -> list[Path]:
    """Write (whole) one experiment file per prior draw: ``OUT/sbi_training/dNNN.toml`` (or, ``held_out``,
    ``OUT/sbi_test/tNN.toml``), each extending the experiment at its draw (a sweep of one point, so
    theta is a column of the tables), ``runs`` runs of ``steps`` frames, and a seed of its own.

    Every simulation has its own seed: had the draws shared run *i*'s seed (a sweep's pairing),
    the posterior would learn the few seeds' noise and be overconfident on any other run
    (docs/hypotheses.md, run 14). Training and held-out draws come from ``SeedSequence([seed, 0])``
    and ``SeedSequence([seed, 1])``.

    Parameters
    ----------
    experiment_path : path
        The experiment file each draw's file extends.
    prior : mapping of str to (float, float)
        The uniform prior: each inferred key's bounds.
    n : int
        The draws.
    runs : int
        The runs of each draw's experiment.
    steps : int
        The frames of each run.
    seed : int
        The study's seed.
    out : path
        The study's folder.
    held_out : bool
        Write the held-out draws (``sbi_test/tNN.toml``) instead of the training ones.

    Returns
    -------
    list of path
        The files written.
    """
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    folder = own_dir(folder, "sbi_test" if held_out else "sbi_training")
    paths = []
    for i, (run_seed, theta) in enumerate(prior_draws(prior, n, np.random.SeedSequence([seed, int(held_out)]))):
        lines = [f"extends = {str(Path(experiment_path).resolve())!r}", f"name = {folder.name!r}", f"runs = {int(runs)}",
                 f"steps = {int(steps)}", f"seed = {run_seed}", "", "[sweep]"]
        lines += [f'"{key}" = [{value!r}]' for key, value in theta.items()]
        path = folder / (f"t{i:02d}.toml" if held_out else f"d{i:03d}.toml")
        atomic_text(path, "\n".join(lines) + "\n")
        paths.append(path)
    return paths


def training_set(folders: Sequence, prior: Mapping[str, tuple[float, float]], n_contexts: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(theta, x) of every run of the results folders: the swept values and the summaries.

    Parameters
    ----------
    folders : sequence of path
        The draws' results folders.
    prior : mapping of str to (float, float)
        The uniform prior: each inferred key's bounds.
    n_contexts : int
        The world's contexts (:func:`summaries`).

    Returns
    -------
    (array of shape (runs, len(prior)), array of shape (runs, summaries))
        theta and x, a row per run.
    """
    from ..results import ResultsStore

    keys = list(prior)
    theta, x = [], []
    for results in folders:
        episodes, _ = ResultsStore(results).load()
        missing = [k for k in keys if k not in episodes]
        if missing:
            raise ConfigError(results, missing[0], "a swept column of the runs", "none")
        for _, run in episodes.groupby(["condition", "run"], sort=True):
            b = Behaviour("run", run["context"].to_numpy(), np.zeros(len(run), np.int64), {}, str(results))
            theta.append(run[keys].iloc[0].to_numpy(dtype=np.float64))
            x.append(summaries(b, n_contexts))
    return np.array(theta).reshape(-1, len(keys)), np.array(x)


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
    """A neural posterior estimator (sbi's NPE, a masked autoregressive flow) trained on (theta, x).

    Parameters
    ----------
    theta : array of shape (runs, len(prior))
        The parameters of the training runs.
    x : array of shape (runs, summaries)
        Their summaries.
    prior : mapping of str to (float, float)
        The uniform prior: each inferred key's bounds.
    seed : int
        torch's seed.
    max_epochs : int
        The most training epochs.

    Returns
    -------
    callable
        ``sample(x_observed, n) -> (n, len(prior)) array``.
    """
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
    """``dataset, param, estimate, ci_low, ci_high``: posterior median and central 95 % interval.

    Parameters
    ----------
    samples : array of shape (n, len(prior))
        Posterior samples.
    prior : mapping of str to (float, float)
        The uniform prior: each inferred key's bounds.
    dataset : str
        The data set's name.

    Returns
    -------
    pandas.DataFrame
        One row per key.
    """
    return pd.DataFrame([{"dataset": dataset, "param": k, "estimate": float(np.median(samples[:, i])),
                          "ci_low": float(np.quantile(samples[:, i], 0.025)),
                          "ci_high": float(np.quantile(samples[:, i], 0.975))} for i, k in enumerate(prior)])


def n_draws(simulations: int, runs: int) -> int:
    """The prior draws that make ``simulations`` training runs of ``runs`` runs each (one line when none).

    Parameters
    ----------
    simulations : int
        The ``--simulations`` given: a multiple of ``runs``, at least two draws.
    runs : int
        The ``--runs`` given: runs per draw.

    Returns
    -------
    int
        ``simulations // runs``.
    """
    if runs < 1:
        raise ConfigError("--runs", None, "an integer >= 1", str(runs))
    if simulations < 2 * runs or simulations % runs:
        raise ConfigError("--simulations", None, f"a multiple of --runs ({runs}), at least 2 draws", str(simulations))
    return simulations // runs


@dataclass
class SBIStudy:
    """NPE of ``condition``'s ``prior`` parameters (what ``neurocur sbi`` runs) inside the folder ``out``:
    each training draw is an experiment (``out/sbi_training/dNNN.toml`` run into ``dNNN/``), each
    held-out draw too (``out/sbi_test/tNN.toml`` into ``tNN/``, one run), computed by ``executor``
    (:func:`~neurocur.experiments.executors.executor_for`), so an interrupted study resumes, run by
    run (a run is short next to the set: no checkpoints within a run). torch is imported only by
    :meth:`fit`, after the runs.

    Parameters
    ----------
    experiment : Experiment
        The loaded experiment.
    condition : str
        The condition simulated.
    prior : mapping of str to (float, float)
        The uniform prior: each inferred key's bounds.
    out : path
        The study's folder.
    steps : int
        The frames of each run.
    seed : int
        The study's seed.
    """

    experiment: object
    condition: str
    prior: dict
    out: Path
    steps: int
    seed: int = 0

    def _run(self, paths: Sequence[Path], executor) -> list[Path]:
        from ..experiments import load_experiment, run_experiment

        for path in paths:
            run_experiment(load_experiment(path), own_dir(path.parent, path.stem), conditions=[self.condition],
                           executor=executor, checkpoint_every=0)
        return [path.with_suffix("") for path in paths]

    def simulate(self, executor, *, simulations: int, runs: int, tests: int = 0) -> tuple[list[Path], list[Path]]:
        """Compute (or resume) the training runs and ``tests`` held-out runs; returns their folders."""
        if tests < 0:
            raise ConfigError("--test", None, "an integer >= 0", str(tests))
        common = {"steps": self.steps, "seed": self.seed, "out": self.out}
        training = draw_experiments(self.experiment.path, self.prior, n=n_draws(simulations, runs), runs=runs, **common)
        held_out = draw_experiments(self.experiment.path, self.prior, n=tests, runs=1, held_out=True, **common) \
            if tests else []
        return self._run(training, executor), self._run(held_out, executor)

    def fit(self, folders: Sequence[Path], n_contexts: int, *, epochs: int = 200):
        """The posterior sampler trained on the runs of ``folders`` (:func:`train`)."""
        theta, x = training_set(folders, self.prior, n_contexts)
        return train(theta, x, self.prior, seed=self.seed, max_epochs=epochs)

    def recovery(self, sample, folders: Sequence[Path], n_contexts: int, n: int = 2000) -> pd.DataFrame:
        """``dataset, param, true, estimate, ci_low, ci_high`` of the held-out runs in ``folders``
        (posterior median and central 95 % interval of ``n`` samples at each run's summaries)."""
        tables = []
        for folder in folders:
            theta, x = training_set([folder], self.prior, n_contexts)
            tables.append(posterior_table(sample(x[0], n), self.prior, folder.name).assign(true=theta[0]))
        columns = ["dataset", "param", "true", "estimate", "ci_low", "ci_high"]
        return pd.concat(tables, ignore_index=True)[columns] if tables else pd.DataFrame(columns=columns)

    def posterior(self, sample, datasets: Sequence[Behaviour], n_contexts: int, n: int = 2000) -> pd.DataFrame:
        """:func:`posterior_table` of every data set."""
        return pd.concat([posterior_table(sample(summaries(b, n_contexts), n), self.prior, b.name) for b in datasets],
                         ignore_index=True)
