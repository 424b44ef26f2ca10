"""Whether two conditions differ: tests on the per-run metrics of :func:`~neurocur.analysis.order.per_run`."""

from __future__ import annotations

import math
from collections.abc import Sequence

import pandas as pd
from scipy import stats as sps

from neurocur.contexts.base import SourceSpec
from neurocur.contexts.synthetic import SYNTHETIC

from .order import BINARY_METRICS, NUMERIC_METRICS, ordinal_columns, per_run, require_order_columns

__all__ = ["compare"]


def _per_run_table(stats_or_tables, spec: SourceSpec) -> pd.DataFrame:
    if isinstance(stats_or_tables, pd.DataFrame):
        return stats_or_tables
    if isinstance(stats_or_tables, Sequence) and len(stats_or_tables) == 2:
        require_order_columns(*stats_or_tables, needed_by="compare")
        return per_run(*stats_or_tables, spec)
    raise ValueError("compare expected a per_run() DataFrame or an (episodes, modules) pair")


def compare(
    stats_or_tables,
    a: str = "curious",
    b: str = "random_switching",
    metric: str | Sequence[str] | None = None,
    spec: SourceSpec = SYNTHETIC,
) -> pd.DataFrame:
    """Test conditions ``a`` against ``b`` on per-run metrics; one row per metric.

    ``stats_or_tables`` is a :func:`~neurocur.analysis.order.per_run` table or an
    ``(episodes, modules)`` pair. ``metric`` defaults to every numeric and binary metric of
    :func:`~neurocur.analysis.order.per_run`.

    * Yes/no metrics (bool columns such as exact_order, unlearnable_stored, first_ok):
      Fisher's exact test (two-sided) on the 2×2 table; effect = sample odds ratio
      (a_yes·b_no)/(a_no·b_yes), which can be 0 or inf.
    * Numeric metrics (n_modules, gated_sources, kendall_tau, ...): two-sided
      Mann–Whitney U on the per-run values (NaN dropped); effect = rank-biserial
      correlation 2U_a/(n_a n_b) − 1, +1 when every run of ``a`` exceeds every run of ``b``.

    Columns: metric, test, a, b, n_a, n_b, value_a, value_b (mean, or proportion),
    statistic, p_value, effect, effect_size.
    """
    runs = _per_run_table(stats_or_tables, spec)
    conditions = sorted(runs["condition"].unique())
    for name in (a, b):
        if name not in conditions:
            raise ValueError(f"compare: condition {name!r} not in the results; have {conditions}")
    if metric is None:
        metrics = [*NUMERIC_METRICS, *ordinal_columns(spec), *BINARY_METRICS]
    else:
        metrics = [metric] if isinstance(metric, str) else list(metric)
    rows = []
    for name in metrics:
        if name not in runs:
            raise ValueError(f"compare: unknown metric {name!r}; per-run columns are {list(runs.columns)}")
        xa = runs.loc[runs["condition"] == a, name]
        xb = runs.loc[runs["condition"] == b, name]
        if xa.dtype == bool and xb.dtype == bool:
            ya, yb = int(xa.sum()), int(xb.sum())
            result = sps.fisher_exact([[ya, len(xa) - ya], [yb, len(xb) - yb]])
            row = {"test": "fisher_exact", "n_a": len(xa), "n_b": len(xb),
                   "value_a": ya / len(xa), "value_b": yb / len(xb),
                   "statistic": float(result.statistic), "p_value": float(result.pvalue),
                   "effect": "odds_ratio", "effect_size": float(result.statistic)}
        else:
            xa, xb = xa.astype(float).dropna(), xb.astype(float).dropna()
            row = {"test": "mann_whitney_u", "n_a": len(xa), "n_b": len(xb),
                   "value_a": xa.mean() if len(xa) else math.nan,
                   "value_b": xb.mean() if len(xb) else math.nan,
                   "statistic": math.nan, "p_value": math.nan,
                   "effect": "rank_biserial", "effect_size": math.nan}
            if len(xa) and len(xb):
                result = sps.mannwhitneyu(xa, xb, alternative="two-sided")
                row.update(statistic=float(result.statistic), p_value=float(result.pvalue),
                           effect_size=2.0 * result.statistic / (len(xa) * len(xb)) - 1.0)
        rows.append({"metric": name, "a": a, "b": b, **row})
    columns = ["metric", "test", "a", "b", "n_a", "n_b", "value_a", "value_b",
               "statistic", "p_value", "effect", "effect_size"]
    return pd.DataFrame(rows, columns=columns)
