"""How each option's share of a subject's free choices moves over time, and in which order the
options peak: the seed paper's claim (a curious learner takes the easy task first, then the
harder ones, and leaves the unlearnable one) asked of a free-choice table (docs/hypotheses.md,
entry 16, on Ten et al. 2021's participants).

The input is a tidy trials table, one row per choice: ``subject``, ``trial`` (order within the
subject) and ``choice`` (an option's name). Each subject's choices are cut into ``n_bins``
consecutive bins of (nearly) equal size; an option's share in a bin is the fraction of the
bin's choices that went to it. Every function works on the ``(subjects, bins, options)`` array
:func:`share_array` returns.

- :func:`peak_bins`: the bin (1-based) of each option's largest share per subject; tied bins
  give their mean position; an option the subject never chose has no peak (NaN).
- :func:`ordered_peaks`: whether a subject's peaks come in a given order, strictly.
- :func:`share_change`: an option's mean share in the later half of the bins minus the earlier.
- :func:`permutation_tests`: both statistics against a null that shuffles each subject's bins in
  time, one shuffle for all options (each bin's shares stay together, each subject's allocation is
  kept), one-sided p = (1 + shuffles at least as extreme) / (1 + shuffles) (Phipson & Smyth 2010),
  Holm's adjustment (Holm 1979) over every test of the call.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from statsmodels.stats.multitest import multipletests

from .bootstrap import BOOTSTRAP_SEED, N_BOOT, bootstrap_ci

__all__ = ["N_PERMUTATIONS", "ordered_peaks", "peak_bins", "permutation_tests", "share_array", "share_change",
           "share_summary"]

#: The default number of shuffles of the permutation tests.
N_PERMUTATIONS = 10_000


def share_array(trials: pd.DataFrame, options: Sequence[str], *, n_bins: int = 10) -> tuple[np.ndarray, list]:
    """Each subject's share of choices per bin and option, shape ``(subjects, n_bins, options)``,
    and the subjects in order of first appearance. Trial *i* of a subject's *n* (in ``trial``
    order) falls in bin ``floor(i * n_bins / n)``, so 250 choices make 10 bins of 25.

    Parameters
    ----------
    trials : pandas.DataFrame
        One row per choice, with the columns ``subject``, ``trial`` (order within the subject)
        and ``choice`` (one of ``options``).
    options : sequence of str
        The options' names, in the order of the array's last axis.
    n_bins : int
        Number of bins each subject's choices are cut into; every subject needs at least this
        many choices.

    Returns
    -------
    shares : numpy.ndarray
        Shape ``(subjects, n_bins, options)``: the fraction of each bin's choices that went to
        each option (each bin's row sums to 1).
    subjects : list
        The subjects, in the order of the array's first axis.

    Raises
    ------
    ValueError
        When a column is missing, a choice is not among ``options``, or a subject has fewer
        than ``n_bins`` choices.
    """
    missing = [c for c in ("subject", "trial", "choice") if c not in trials.columns]
    if missing:
        raise ValueError(f"share_array expected the columns subject, trial, choice, got no {missing[0]!r}")
    unknown = sorted(set(trials["choice"]) - set(options))
    if unknown:
        raise ValueError(f"share_array expected choices among {list(options)}, got {unknown[0]!r}")
    code = {name: k for k, name in enumerate(options)}
    subjects = list(pd.unique(trials["subject"]))
    shares = np.zeros((len(subjects), n_bins, len(options)))
    for s, (subject, rows) in enumerate(trials.groupby("subject", sort=False)):
        choices = rows.sort_values("trial", kind="stable")["choice"].map(code).to_numpy()
        n = len(choices)
        if n < n_bins:
            raise ValueError(f"share_array expected at least {n_bins} choices per subject, got {n} for {subject!r}")
        bins = np.arange(n) * n_bins // n
        counts = np.zeros((n_bins, len(options)))
        np.add.at(counts, (bins, choices), 1.0)
        shares[s] = counts / np.bincount(bins, minlength=n_bins)[:, None]
    return shares, subjects


def share_summary(shares: np.ndarray, options: Sequence[str], *, confidence: float = 0.95, n_boot: int = N_BOOT,
                  seed: int = BOOTSTRAP_SEED) -> pd.DataFrame:
    """One row per bin and option: ``bin`` (1-based), ``option``, ``mean`` share over subjects,
    ``ci_low``/``ci_high`` (percentile bootstrap over subjects,
    :func:`~neurocur.analysis.stats.bootstrap.bootstrap_ci`) and ``n`` subjects.

    Parameters
    ----------
    shares : numpy.ndarray
        Shape ``(subjects, bins, options)``, as ``share_array`` returns it.
    options : sequence of str
        The options' names, in the order of the last axis.
    confidence : float
        Coverage of each bootstrap interval, in (0, 1).
    n_boot : int
        Number of bootstrap resamples of each interval.
    seed : int
        Seed of each interval's resamples.

    Returns
    -------
    pandas.DataFrame
        Columns ``bin``, ``option``, ``mean``, ``ci_low``, ``ci_high``, ``n``; bins in order,
        options in ``options``' order within each bin.
    """
    rows = []
    for b in range(shares.shape[1]):
        for k, option in enumerate(options):
            low, high = bootstrap_ci(shares[:, b, k], n_boot=n_boot, confidence=confidence, seed=seed)
            rows.append({"bin": b + 1, "option": option, "mean": float(shares[:, b, k].mean()), "ci_low": low,
                         "ci_high": high, "n": shares.shape[0]})
    return pd.DataFrame(rows)


def peak_bins(shares: np.ndarray) -> np.ndarray:
    """Each subject's peak bin per option, shape ``(subjects, options)``: the 1-based bin of the
    largest share, the mean position when several bins tie, NaN for an option never chosen.

    Parameters
    ----------
    shares : numpy.ndarray
        Shape ``(subjects, bins, options)``, as ``share_array`` returns it.

    Returns
    -------
    numpy.ndarray
        Shape ``(subjects, options)``, float: the peak bins (1-based), NaN where an option was
        never chosen.
    """
    top = shares.max(axis=1, keepdims=True)
    at_top = shares == top
    position = np.arange(1, shares.shape[1] + 1)[None, :, None]
    peak = (at_top * position).sum(axis=1) / at_top.sum(axis=1)
    return np.where(top[:, 0, :] > 0, peak, np.nan)


def ordered_peaks(peaks: np.ndarray, order: Sequence[int]) -> np.ndarray:
    """Per subject: 1.0 when the peaks of the options ``order`` (indices) rise strictly in that
    order, 0.0 when they do not, NaN when one of them has no peak.

    Parameters
    ----------
    peaks : numpy.ndarray
        Shape ``(subjects, options)``, as ``peak_bins`` returns it.
    order : sequence of int
        Indices of the options (the last axis of ``peaks``), in the order their peaks should come.

    Returns
    -------
    numpy.ndarray
        Shape ``(subjects,)``: 1.0, 0.0 or NaN per subject.
    """
    chosen = peaks[:, list(order)]
    ordered = np.all(np.diff(chosen, axis=1) > 0, axis=1).astype(float)
    return np.where(np.isnan(chosen).any(axis=1), np.nan, ordered)


def share_change(shares: np.ndarray, option: int) -> np.ndarray:
    """Per subject: the option's mean share over the later half of the bins minus the earlier
    half (the middle bin left out when their number is odd).

    Parameters
    ----------
    shares : numpy.ndarray
        Shape ``(subjects, bins, options)``, as ``share_array`` returns it.
    option : int
        Index of the option (the last axis of ``shares``).

    Returns
    -------
    numpy.ndarray
        Shape ``(subjects,)``: the change in share, positive for a rise.
    """
    half = shares.shape[1] // 2
    return shares[:, -half:, option].mean(axis=1) - shares[:, :half, option].mean(axis=1)


#: Shuffles drawn and scored together (memory: this many copies of the shares).
_CHUNK = 256


def _statistics(shares: np.ndarray, order: Sequence[int], falling: int) -> np.ndarray:
    """The two statistics of each of a stack of tables, shape ``(..., subjects, bins, options)`` ->
    ``(..., 2)``: subjects with ordered peaks, mean change in the falling option's share."""
    flat = shares.reshape(-1, *shares.shape[-2:])
    lead = shares.shape[:-3]
    ordered = ordered_peaks(peak_bins(flat), order).reshape(*lead, shares.shape[-3])
    change = share_change(flat, falling).reshape(*lead, shares.shape[-3])
    return np.stack([np.nansum(ordered, axis=-1), change.mean(axis=-1)], axis=-1)


def permutation_tests(groups: Mapping[str, np.ndarray], order: Sequence[int], falling: int, *,
                      n_permutations: int = N_PERMUTATIONS, seed: int = 2021) -> pd.DataFrame:
    """For each ``{group: shares}``: the number of subjects whose peaks follow ``order`` (tested
    for more than the null) and the mean :func:`share_change` of option ``falling`` (tested for
    a fall), each against shuffles of every subject's bins in time. One row per group and
    statistic: ``observed``, ``n`` (subjects that count: those with all the peaks for the order),
    ``null_mean``, ``p_value`` (one-sided, the claimed direction), ``p_opposite`` (one-sided, the
    other direction) and ``p_holm`` (Holm over all the rows). Deterministic by ``seed``.

    Parameters
    ----------
    groups : mapping of str to numpy.ndarray
        ``{group name: shares}``, each of shape ``(subjects, bins, options)`` as ``share_array``
        returns it; group *g* (in the mapping's order) draws from
        ``numpy.random.default_rng([seed, g])``.
    order : sequence of int
        Indices of the options whose peaks should rise in that order (as in ``ordered_peaks``).
    falling : int
        Index of the option whose share should fall (as in ``share_change``).
    n_permutations : int
        Number of shuffles of each group's bins.
    seed : int
        Seed of the shuffles.

    Returns
    -------
    pandas.DataFrame
        Columns ``group``, ``statistic`` (``"ordered peaks"`` or ``"change in share"``),
        ``observed``, ``n``, ``null_mean``, ``p_value``, ``p_opposite``, ``p_holm``; two rows
        per group.
    """
    rows = []
    for g, (name, shares) in enumerate(groups.items()):
        rng = np.random.default_rng([seed, g])
        observed = _statistics(shares, order, falling)
        null = np.empty((n_permutations, 2))
        for start in range(0, n_permutations, _CHUNK):
            size = min(_CHUNK, n_permutations - start)
            times = rng.permuted(np.broadcast_to(np.arange(shares.shape[1]), (size, *shares.shape[:2])), axis=-1)
            shuffled = np.take_along_axis(shares[None], times[..., None], axis=2)
            null[start:start + size] = _statistics(shuffled, order, falling)
        n_peaks = int((~np.isnan(ordered_peaks(peak_bins(shares), order))).sum())
        for j, (statistic, sign, n) in enumerate((("ordered peaks", 1.0, n_peaks),
                                                  ("change in share", -1.0, shares.shape[0]))):
            claimed = sign * (null[:, j] - observed[j]) >= -1e-12
            other = sign * (null[:, j] - observed[j]) <= 1e-12
            rows.append({"group": name, "statistic": statistic, "observed": observed[j], "n": n,
                         "null_mean": float(null[:, j].mean()),
                         "p_value": (1 + int(claimed.sum())) / (1 + n_permutations),
                         "p_opposite": (1 + int(other.sum())) / (1 + n_permutations)})
    table = pd.DataFrame(rows)
    table["p_holm"] = multipletests(table["p_value"], method="holm")[1] if len(table) else []
    return table
