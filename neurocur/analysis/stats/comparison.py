"""Whether conditions differ: tests on the per-run metrics of :func:`~neurocur.analysis.stats.order.per_run`.

Run *i* of every condition and sweep point uses the same seed, hence the same world, so
:func:`compare` pairs the runs of two conditions by ``run`` and tests the paired
differences (:mod:`~neurocur.analysis.stats.significance`: Wilcoxon signed-rank, Wilcoxon 1945,
for numbers; McNemar's exact test, McNemar 1947, for yes/no outcomes), with percentile
bootstrap intervals over the pairs (:mod:`~neurocur.analysis.stats.bootstrap`, Efron &
Tibshirani 1993). ``paired=False`` keeps the unpaired tests for data that are not paired
(Mann–Whitney U, Fisher's exact test).

Comparing many conditions, sweep points or metrics, :func:`adjust_pvalues` adjusts the
p-values of the whole table for multiple comparisons: Holm's step-down method (Holm 1979,
the default; controls the family-wise error rate) or Benjamini–Hochberg (Benjamini &
Hochberg 1995; controls the false discovery rate), both by
:func:`statsmodels.stats.multitest.multipletests`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd
from statsmodels.stats.multitest import multipletests

from .bootstrap import BOOTSTRAP_SEED, N_BOOT, paired_bootstrap_ci, unpaired_bootstrap_ci
from .order import BINARY_METRICS, NUMERIC_METRICS, ordinal_columns
from .significance import fisher_exact, mann_whitney, mcnemar_exact, wilcoxon_signed_rank

__all__ = ["COMPARE_COLUMNS", "ADJUSTMENTS", "ADJUSTMENT_NAMES", "adjustment", "compare", "compare_conditions",
           "adjust_pvalues"]

#: The columns of :func:`compare` (and of every table built from it), in order.
COMPARE_COLUMNS = [
    "metric", "test", "method", "a", "b", "n_a", "n_b", "n_pairs", "n_nonzero",
    "value_a", "ci_a_low", "ci_a_high", "value_b", "ci_b_low", "ci_b_high",
    "difference", "ci_diff_low", "ci_diff_high",
    "statistic", "p_value", "p_adjusted", "adjustment", "n_tests", "effect", "effect_size",
]
#: The accepted names of the multiple-comparison adjustments → statsmodels' method (None: no adjustment).
ADJUSTMENTS = {"holm": "holm", "bh": "fdr_bh", "fdr_bh": "fdr_bh", "none": None}
#: Each adjustment's name and reference, by the ``adjustment`` column's value.
ADJUSTMENT_NAMES = {"holm": ("Holm", "Holm 1979"), "fdr_bh": ("Benjamini–Hochberg", "Benjamini & Hochberg 1995"),
                    "none": ("unadjusted", "")}


def adjustment(method: str | None) -> str | None:
    """statsmodels' name of the adjustment ``method`` (a key of :data:`ADJUSTMENTS`; None: no adjustment).

    Parameters
    ----------
    method : str or None
        ``"holm"``, ``"bh"``, ``"fdr_bh"``, ``"none"`` or None.

    Returns
    -------
    str or None
        statsmodels' name, or None.
    """
    key = "none" if method is None else str(method).lower()
    if key not in ADJUSTMENTS:
        raise ValueError(f"unknown p-value adjustment {method!r}; use one of {list(ADJUSTMENTS)} or None")
    return ADJUSTMENTS[key]


def adjust_pvalues(table: pd.DataFrame, method: str | None = "holm") -> pd.DataFrame:
    """``table`` with ``p_adjusted``, ``adjustment`` and ``n_tests`` set for its ``p_value`` column.

    The family is every row of ``table`` with a p-value (NaN p-values stay NaN and are not
    counted): ``n_tests`` is its size. ``method``: ``"holm"`` (Holm 1979, the default),
    ``"bh"`` / ``"fdr_bh"`` (Benjamini & Hochberg 1995) or ``None`` / ``"none"`` (p_adjusted
    = p_value); ``adjustment`` names statsmodels' method (``"holm"``, ``"fdr_bh"``, ``"none"``).
    Adjusted p-values are never below the raw ones.

    Parameters
    ----------
    table : pandas.DataFrame
        Rows with a ``p_value`` column.
    method : str or None
        The adjustment (:func:`adjustment`).

    Returns
    -------
    pandas.DataFrame
        A copy with the adjusted p-values.
    """
    name = adjustment(method)
    out = table.copy()
    p = out["p_value"].to_numpy(dtype=float)
    ok = ~np.isnan(p)
    adjusted = p.copy()
    if name is not None and ok.any():
        adjusted[ok] = multipletests(p[ok], method=name)[1]
    out["p_adjusted"] = adjusted
    out["adjustment"] = name or "none"
    out["n_tests"] = int(ok.sum())
    return out


def _values(runs: pd.DataFrame, condition: str, metric: str, paired: bool) -> pd.Series:
    rows = runs.loc[runs["condition"] == condition]
    return (rows.set_index("run") if paired else rows)[metric]


def _check_pairable(runs: pd.DataFrame, a: str, b: str) -> None:
    if "run" not in runs:
        raise ValueError("compare: paired=True pairs the runs by their 'run' column, which this table lacks; "
                         "pass paired=False for data that are not paired")
    for name in (a, b):
        dup = runs.loc[runs["condition"] == name, "run"].duplicated()
        if dup.any():
            raise ValueError(f"compare: condition {name!r} has run(s) "
                             f"{sorted(runs.loc[runs['condition'] == name, 'run'][dup].unique())} more than once; "
                             "pairing by run needs one row per (condition, run)")


def _one(runs: pd.DataFrame, a: str, b: str, metric: str, paired: bool, boot: dict) -> dict:
    xa, xb = _values(runs, a, metric, paired), _values(runs, b, metric, paired)
    binary = xa.dtype == bool and xb.dtype == bool
    if not binary:
        xa, xb = xa.astype(float).dropna(), xb.astype(float).dropna()
    row: dict = {"n_a": len(xa), "n_b": len(xb)}
    if paired:
        pairs = pd.concat([xa.rename("a"), xb.rename("b")], axis=1, join="inner")
        va, vb = pairs["a"].to_numpy(dtype=float), pairs["b"].to_numpy(dtype=float)
        result = (mcnemar_exact if binary else wilcoxon_signed_rank)(va, vb)
        cis = paired_bootstrap_ci(va, vb, **boot)
        row.update(n_pairs=len(pairs), n_nonzero=result["n_nonzero"])
    else:
        va, vb = xa.to_numpy(dtype=float), xb.to_numpy(dtype=float)
        result = (fisher_exact if binary else mann_whitney)(va, vb)
        cis = unpaired_bootstrap_ci(va, vb, **boot)
        row.update(n_pairs=math.nan, n_nonzero=math.nan)
    mean_a = float(va.mean()) if len(va) else math.nan
    mean_b = float(vb.mean()) if len(vb) else math.nan
    row.update(value_a=mean_a, ci_a_low=cis["a"][0], ci_a_high=cis["a"][1],
               value_b=mean_b, ci_b_low=cis["b"][0], ci_b_high=cis["b"][1],
               difference=mean_a - mean_b, ci_diff_low=cis["difference"][0], ci_diff_high=cis["difference"][1])
    return {"metric": metric, "a": a, "b": b, **row,
            **{k: result[k] for k in ("test", "method", "statistic", "p_value", "effect", "effect_size")}}


def compare(
    runs: pd.DataFrame,
    a: str,
    b: str,
    metric: str | Sequence[str] | None = None,
    *,
    paired: bool = True,
    adjust: str | None = "holm",
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """Test condition ``a`` against ``b`` on per-run metrics; one row per metric (:data:`COMPARE_COLUMNS`).

    ``runs`` is a table of per-run metrics, one row per (condition, run): e.g.
    :func:`~neurocur.analysis.stats.order.per_run` or
    :func:`~neurocur.analysis.stats.efficiency.efficiency_per_run`. ``metric`` defaults to every
    numeric and yes/no metric of :func:`~neurocur.analysis.stats.order.per_run`.

    **Paired** (the default): the runs of ``a`` and ``b`` are paired by ``run``; a run present
    in only one condition (or, for numbers, NaN in either) is dropped, ``n_pairs`` counts the
    pairs left and ``n_a``/``n_b`` the runs of each condition with a value.

    * numbers (n_modules, gated_sources, kendall_tau, ...): two-sided Wilcoxon signed-rank
      test of the differences a − b (zero differences dropped, ``n_nonzero`` kept; all zero
      gives p = 1; see :func:`~neurocur.analysis.stats.significance.wilcoxon_signed_rank`);
      effect = matched-pairs rank-biserial correlation, +1 when ``a`` is higher on every
      pair that differs;
    * yes/no (exact_order, unlearnable_stored, first_ok, ...): McNemar's exact test on the
      ``n_nonzero`` discordant pairs; effect = their odds ratio n_ab/n_ba (0 or inf at the
      edges), and ``difference`` is the difference in proportions.

    **Unpaired** (``paired=False``): two-sided Mann–Whitney U (effect = rank-biserial
    2U_a/(n_a n_b) − 1) and Fisher's exact test (effect = sample odds ratio), as before
    pairing was the default; ``n_pairs`` and ``n_nonzero`` are NaN.

    ``value_a``/``value_b`` are the means (proportions) over the runs the test used (the pairs
    when paired), ``difference`` = value_a − value_b, each with a percentile bootstrap
    interval (``ci_*``; ``n_boot`` resamples at ``confidence``, from ``seed``: the pairs are
    resampled together when paired). ``test`` says in words what was done (e.g.
    "Wilcoxon signed-rank (paired by run, n=25 pairs; ...)"), ``method`` as a short code.
    ``p_adjusted`` adjusts ``p_value`` over the metrics of this call (``adjust``: Holm by
    default, see :func:`adjust_pvalues`).

    Parameters
    ----------
    runs : pandas.DataFrame
        Per-run metrics, one row per (condition, run).
    a, b : str
        The conditions compared.
    metric : str or sequence of str, optional
        The metrics tested (default: every numeric and yes/no metric of :func:`~neurocur.analysis.stats.order.per_run`).
    paired : bool
        Pair the runs by ``run`` (the default) or test them as independent samples.
    adjust : str or None
        The adjustment of ``p_value`` (:func:`adjust_pvalues`).
    n_boot : int
        The bootstrap resamples of each interval.
    confidence : float
        The intervals' coverage.
    seed : int
        The bootstrap's seed.

    Returns
    -------
    pandas.DataFrame
        One row per metric.
    """
    conditions = sorted(runs["condition"].unique())
    for name in (a, b):
        if name not in conditions:
            raise ValueError(f"compare: condition {name!r} not in the results; have {conditions}")
    if paired:
        _check_pairable(runs, a, b)
    if metric is None:
        metrics = [*NUMERIC_METRICS, *ordinal_columns(runs), *BINARY_METRICS]
    else:
        metrics = [metric] if isinstance(metric, str) else list(metric)
    boot = {"n_boot": n_boot, "confidence": confidence, "seed": seed}
    rows = []
    for name in metrics:
        if name not in runs:
            raise ValueError(f"compare: unknown metric {name!r}; per-run columns are {list(runs.columns)}")
        rows.append(_one(runs, a, b, name, paired, boot))
    return adjust_pvalues(pd.DataFrame(rows, columns=COMPARE_COLUMNS), adjust)


def compare_conditions(
    runs: pd.DataFrame,
    reference: str,
    others: Sequence[str] | None = None,
    metric: str | Sequence[str] | None = None,
    *,
    paired: bool = True,
    adjust: str | None = "holm",
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """:func:`compare` of ``reference`` (as ``a``) against every other condition (``others``, all by
    default, in name order), one table adjusted over all its rows (every condition × metric).

    Columns: :data:`COMPARE_COLUMNS`; empty (with those columns) when there is nothing to compare.

    Parameters
    ----------
    runs : pandas.DataFrame
        Per-run metrics, one row per (condition, run).
    reference : str
        The condition tested against the others.
    others : sequence of str, optional
        The other conditions (default: all, in name order).
    metric : str or sequence of str, optional
        As in :func:`compare`.
    paired : bool
        Pair the runs by ``run`` (the default) or test them as independent samples.
    adjust : str or None
        The adjustment of ``p_value`` (:func:`adjust_pvalues`).
    n_boot : int
        The bootstrap resamples of each interval.
    confidence : float
        The intervals' coverage.
    seed : int
        The bootstrap's seed.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`COMPARE_COLUMNS`.
    """
    conditions = sorted(runs["condition"].unique())
    if reference not in conditions:
        raise ValueError(f"compare_conditions: condition {reference!r} not in the results; have {conditions}")
    others = [c for c in conditions if c != reference] if others is None else list(others)
    tables = [compare(runs, reference, other, metric, paired=paired, adjust=None, n_boot=n_boot,
                      confidence=confidence, seed=seed) for other in others]
    if not tables:
        return pd.DataFrame(columns=COMPARE_COLUMNS)
    return adjust_pvalues(pd.concat(tables, ignore_index=True), adjust)
