"""Percentile bootstrap intervals over runs (Efron & Tibshirani 1993, ch. 13).

A condition's mean (or proportion, for yes/no outcomes) is resampled by drawing its runs
with replacement; a paired difference by drawing whole pairs (run *i* of both conditions
together, so the shared per-run world stays in every resample); an unpaired difference
by drawing each condition's runs separately. The interval is the ``(1 − confidence)/2``
and ``(1 + confidence)/2`` quantiles of the ``n_boot`` resampled means.

**Reproducible.** Every interval draws from a fresh ``numpy.random.default_rng(seed)``,
:data:`BOOTSTRAP_SEED` unless told, so the same values, ``n_boot``, ``confidence`` and
``seed`` always give the same interval, whatever else was computed before it.

A percentile interval of a proportion observed at 0/n or n/n collapses to that point;
:func:`~neurocur.analysis.stats.order.clopper_pearson` (the order counts' interval) is exact there.
NaN values are dropped (pairs with a NaN on either side); no values give ``(nan, nan)``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["BOOTSTRAP_SEED", "N_BOOT", "bootstrap_ci", "paired_bootstrap_ci", "unpaired_bootstrap_ci"]

#: The default seed of every bootstrap interval (the year of the paper).
BOOTSTRAP_SEED = 2013
#: The default number of resamples.
N_BOOT = 2000

_NAN = (math.nan, math.nan)


def _check(n_boot: int, confidence: float) -> None:
    if int(n_boot) != n_boot or n_boot < 1:
        raise ValueError(f"the bootstrap expected a positive integer n_boot, got {n_boot!r}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"the bootstrap expected 0 < confidence < 1, got {confidence}")


def _percentile(means: np.ndarray, confidence: float) -> tuple[float, float]:
    low, high = np.quantile(means, [(1.0 - confidence) / 2.0, (1.0 + confidence) / 2.0])
    return (float(low), float(high))


def _resample(n: int, n_boot: int, rng: np.random.Generator) -> np.ndarray:
    return rng.integers(0, n, size=(int(n_boot), n))


def bootstrap_ci(
    values, *, n_boot: int = N_BOOT, confidence: float = 0.95, seed: int = BOOTSTRAP_SEED
) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of ``values`` (runs resampled with replacement).

    Parameters
    ----------
    values : array_like
        One value per run; NaN values are dropped.
    n_boot : int
        Number of resamples.
    confidence : float
        Coverage of the interval, in (0, 1).
    seed : int
        Seed of the fresh ``numpy.random.default_rng`` the resamples draw from.

    Returns
    -------
    tuple of float
        The interval's ``(low, high)``; ``(nan, nan)`` when no values are left.
    """
    _check(n_boot, confidence)
    x = np.asarray(values, dtype=float)
    x = x[~np.isnan(x)]
    if len(x) == 0:
        return _NAN
    return _percentile(x[_resample(len(x), n_boot, np.random.default_rng(seed))].mean(axis=1), confidence)


def paired_bootstrap_ci(
    x, y, *, n_boot: int = N_BOOT, confidence: float = 0.95, seed: int = BOOTSTRAP_SEED
) -> dict[str, tuple[float, float]]:
    """Percentile bootstrap intervals of paired data, resampling pairs.

    Parameters
    ----------
    x, y : array_like
        1-d, of the same length: ``x[i]`` and ``y[i]`` are one pair (the same run of two
        conditions). Pairs with a NaN on either side are dropped.
    n_boot : int
        Number of resamples.
    confidence : float
        Coverage of the interval, in (0, 1).
    seed : int
        Seed of the fresh ``numpy.random.default_rng`` the resamples draw from.

    Returns
    -------
    dict
        ``{"a": ..., "b": ..., "difference": ...}``: the intervals of the mean of ``x``, of ``y``
        and of the mean paired difference ``mean(x − y)``, all from the same resampled pairs.
    """
    _check(n_boot, confidence)
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"paired_bootstrap_ci needs two 1-d arrays of the same length, got {x.shape} and {y.shape}")
    keep = ~(np.isnan(x) | np.isnan(y))
    x, y = x[keep], y[keep]
    if len(x) == 0:
        return {"a": _NAN, "b": _NAN, "difference": _NAN}
    idx = _resample(len(x), n_boot, np.random.default_rng(seed))
    mean_x, mean_y = x[idx].mean(axis=1), y[idx].mean(axis=1)
    return {"a": _percentile(mean_x, confidence), "b": _percentile(mean_y, confidence),
            "difference": _percentile(mean_x - mean_y, confidence)}


def unpaired_bootstrap_ci(
    x, y, *, n_boot: int = N_BOOT, confidence: float = 0.95, seed: int = BOOTSTRAP_SEED
) -> dict[str, tuple[float, float]]:
    """Percentile bootstrap intervals of two independent samples, each resampled on its own.

    Parameters
    ----------
    x, y : array_like
        The two samples, of any lengths; NaN values are dropped.
    n_boot : int
        Number of resamples.
    confidence : float
        Coverage of the interval, in (0, 1).
    seed : int
        Seed of the fresh ``numpy.random.default_rng`` the resamples draw from.

    Returns
    -------
    dict
        ``{"a": ..., "b": ..., "difference": ...}``: the intervals of the mean of ``x``,
        of ``y`` (each as :func:`bootstrap_ci` gives it) and of ``mean(x) − mean(y)``.
    """
    _check(n_boot, confidence)
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    x, y = x[~np.isnan(x)], y[~np.isnan(y)]
    out = {"a": bootstrap_ci(x, n_boot=n_boot, confidence=confidence, seed=seed),
           "b": bootstrap_ci(y, n_boot=n_boot, confidence=confidence, seed=seed), "difference": _NAN}
    if len(x) and len(y):
        rng = np.random.default_rng(seed)
        mean_x = x[_resample(len(x), n_boot, rng)].mean(axis=1)
        mean_y = y[_resample(len(y), n_boot, rng)].mean(axis=1)
        out["difference"] = _percentile(mean_x - mean_y, confidence)
    return out
