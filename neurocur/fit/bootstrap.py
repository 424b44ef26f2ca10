"""Parametric bootstrap intervals of a maximum-likelihood fit (Efron & Tibshirani 1993, "An Introduction to the
Bootstrap", chapters 6 and 13: the parametric bootstrap and the percentile interval).

Given a data set's fit theta-hat, :func:`parametric_bootstrap` simulates ``replicates`` data sets of the
same length at theta-hat with the experiment condition's circuit (:func:`~neurocur.fit.study.simulate`;
replicate r's seed is child r of ``numpy.random.SeedSequence(seed).spawn(replicates)``), replays each
as the data set was replayed (:func:`~neurocur.fit.study.replay_of`, full or signal replay), refits
each by :func:`~neurocur.fit.mle.fit_ml` without intervals, and reports per parameter the central
percentile interval at ``level``: the (1 - level)/2 and (1 + level)/2 quantiles of the B refitted
values. The interval needs no asymptotics (Wilks' theorem, on which the profile-likelihood
interval of :mod:`neurocur.fit.mle` rests), so it stays honest near a bound and along a ridge
where two parameters trade off (the softmax gain and eq 14's alpha), but it inherits the
estimator's bias, and under signal replay the replicates' signal is the circuit's own (the region
the replay replaces simulates it), so it also assumes the circuit's model of that signal.

Cost: B simulations, replays and refits per data set (B = 200 is 200 fits, against one fit and a
profile per parameter for the profile interval).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..config import ConfigError
from .mle import fit_ml
from .study import replay_of, simulate

__all__ = ["Bootstrap", "parametric_bootstrap", "percentile_interval"]


@dataclass
class Bootstrap:
    """A data set's bootstrap (:func:`parametric_bootstrap`).

    Parameters
    ----------
    dataset : str
        The data set's name.
    ci : dict of str to (float, float)
        The percentile interval of each fitted key.
    replicates : pandas.DataFrame
        The tidy table ``dataset, replicate, param, estimate`` of the refitted values.
    """

    dataset: str
    ci: dict
    replicates: pd.DataFrame


def percentile_interval(values, level: float = 0.95) -> tuple[float, float]:
    """The central percentile interval at ``level`` of bootstrap ``values`` (Efron & Tibshirani 1993, chapter 13).

    Parameters
    ----------
    values : array_like of float
        The bootstrap replicates of one parameter.
    level : float
        The interval's coverage: the (1 - level)/2 and (1 + level)/2 quantiles.

    Returns
    -------
    (float, float)
        The interval's ends.
    """
    lo, hi = np.quantile(np.asarray(values, dtype=np.float64), [(1 - level) / 2, (1 + level) / 2])
    return float(lo), float(hi)


def parametric_bootstrap(condition, estimate: Mapping[str, float], n_episodes: int,
                         bounds: Mapping[str, tuple[float, float]], *, replicates: int = 200, level: float = 0.95,
                         seed: int | Sequence[int] = 0, starts: int = 3, decision: str = "LC",
                         signal: tuple[str, str] | None = None, dataset: str = "sim") -> Bootstrap:
    """Percentile intervals for the fitted ``bounds`` keys from ``replicates`` data sets of ``n_episodes``
    simulated at ``estimate`` (module docstring).

    Parameters
    ----------
    condition : Condition
        The experiment condition whose circuit simulates and replays the data sets.
    estimate : mapping of str to float
        The data set's fit theta-hat, at which the replicates are simulated.
    n_episodes : int
        The episodes of each simulated data set (the data set's length).
    bounds : mapping of str to (float, float)
        The fitted keys and their bounds, as in :func:`~neurocur.fit.mle.fit_ml`.
    replicates : int
        B, the simulated data sets (at least 2).
    level : float
        The intervals' coverage.
    seed : int or sequence of int
        Replicate r's seed is child r of ``numpy.random.SeedSequence(seed).spawn(replicates)``.
    starts : int
        The local searches of each refit.
    decision : str
        The region whose decisions are the data.
    signal : (str, str), optional
        (region, column): signal replay, as the data set was fitted.
    dataset : str
        The name in the table's rows.

    Returns
    -------
    Bootstrap
        The intervals and the refitted values.
    """
    if not isinstance(replicates, (int, np.integer)) or replicates < 2:
        raise ConfigError("--bootstrap", None, "a number of bootstrap replicates of at least 2", repr(replicates))
    keys = list(bounds)
    theta = {k: float(estimate[k]) for k in keys}
    rows = []
    for r, child in enumerate(np.random.SeedSequence(seed).spawn(replicates)):
        behaviour, _ = simulate(condition, theta, child, n_episodes, decision=decision, signal=signal,
                                name=f"{dataset}/b{r}")
        fit = fit_ml(replay_of(condition, behaviour, child, keys, decision=decision, signal=signal), bounds,
                     starts=starts, seed=r, ci=None, dataset=behaviour.name)
        rows += [{"dataset": dataset, "replicate": r, "param": k, "estimate": fit.estimate[k]} for k in keys]
    table = pd.DataFrame(rows, columns=["dataset", "replicate", "param", "estimate"])
    ci = {k: percentile_interval(table.loc[table["param"] == k, "estimate"], level) for k in keys}
    return Bootstrap(dataset, ci, table)
