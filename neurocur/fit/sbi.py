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
posterior is sampled at the observed data's summaries. Install with ``pip install neurocur[fit]``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import ConfigError, extra
from .data import Behaviour

__all__ = ["summaries", "train", "training_experiment", "training_set"]

#: the summary statistics, in order (:func:`summaries`)
SUMMARY_NAMES = ("switch_rate", "switch_rate_first_half", "switch_rate_second_half", "mean_run_length_log",
                 "entropy_of_contexts")


def summaries(behaviour: Behaviour, n_contexts: int) -> np.ndarray:
    """x of a data set: the share of decisions that leave the context (overall, first and second
    half), the log of the mean number of episodes per stay, the entropy of the share of episodes in
    each context (bits), then the share of episodes in each context (:data:`SUMMARY_NAMES` + shares)."""
    c = np.asarray(behaviour.contexts)
    moved = c[1:] != c[:-1]
    half = len(moved) // 2
    share = np.bincount(c, minlength=n_contexts) / len(c)
    nz = share[share > 0]
    runs = 1 + int(moved.sum())
    return np.concatenate([[moved.mean(), moved[:half].mean(), moved[half:].mean(), np.log(len(c) / runs),
                            -(nz * np.log2(nz)).sum()], share])


def training_experiment(experiment_path, condition: str, prior: Mapping[str, tuple[float, float]], *,
                        n_values: int, runs: int, steps: int, seed: int, out) -> Path:
    """Write ``OUT/sbi_training.toml``: the experiment (extended), only ``condition``, swept over
    ``n_values`` values of each prior parameter drawn uniformly (seeded), ``runs`` runs per point of
    ``steps`` frames. With several parameters the points are the product of their values."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    lines = [f"extends = {str(Path(experiment_path).resolve())!r}", 'name = "sbi_training"',
             f"runs = {int(runs)}", f"steps = {int(steps)}", f"seed = {int(seed)}", "", "[sweep]"]
    for key, (low, high) in prior.items():
        if not low < high:
            raise ConfigError("prior", key, "LOW < HIGH", f"{low}:{high}")
        values = np.sort(rng.uniform(low, high, n_values))
        lines.append(f'"{key}" = [{", ".join(repr(float(v)) for v in values)}]')
    path = out / "sbi_training.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


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
