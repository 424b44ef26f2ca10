"""The summaries of a results folder: the order table beside the paper's numbers, and ``summary.json``.

Both gather the statistics of :mod:`~neurocur.analysis.order`,
:mod:`~neurocur.analysis.learning_time` and :mod:`~neurocur.analysis.comparison`;
:func:`order_table` sets the paper's numbers (:mod:`~neurocur.analysis.paper`) beside them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from neurocur.contexts.base import SourceSpec
from neurocur.contexts.synthetic import SYNTHETIC

from . import paper
from .comparison import compare
from .learning_time import learning_time_summary, require_learning_columns
from .order import condition_summary, order_counts, per_run, require_order_columns

__all__ = ["order_table", "summary"]


def _mean_sd(mean: float, sd: float) -> str:
    if math.isnan(mean):
        return "—"
    return f"{mean:.2f}" if math.isnan(sd) else f"{mean:.2f} ± {sd:.2f}"


def _paper_cell(numbers: Mapping[str, paper.Reported], label: str) -> str:
    reported = numbers.get(label)
    return "—" if reported is None else reported.cell()


def order_table(episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC) -> pd.DataFrame:
    """The compact per-condition table printed by the CLI, beside the paper's numbers.

    Rows: the order outcomes ("k/n"), modules per run, learnable sources gated per run and
    Kendall τ (mean ± sd), learning time per learnable source (epochs, mean ± sd).
    Columns: "paper" (curious agent, :data:`~neurocur.analysis.paper.SYNTHETIC_CURIOUS`),
    "paper (random)" (:data:`~neurocur.analysis.paper.SYNTHETIC_RANDOM`), then one column
    per condition. The paper columns are filled only for the synthetic world.
    """
    require_order_columns(episodes, modules, needed_by="order_table")
    require_learning_columns(episodes, modules, needed_by="order_table")
    counts = order_counts(episodes, modules, spec)
    means = condition_summary(episodes, modules, spec).set_index(["condition", "metric"])
    times = learning_time_summary(episodes, modules, spec).set_index(["condition", "source"])
    conditions = sorted(episodes["condition"].unique())
    table: dict[str, dict[str, str]] = {}
    for row in counts.itertuples(index=False):
        table.setdefault(row.outcome, {})[row.condition] = f"{row.k}/{row.n}"
    for metric, label in (("n_modules", "modules per run"), ("gated_sources", "learnable sources gated"),
                          ("kendall_tau", "Kendall τ vs Ω")):
        for condition in conditions:
            m = means.loc[(condition, metric)]
            table.setdefault(label, {})[condition] = _mean_sd(m["mean"], m["sd"])
    for source in spec.learnable:
        for condition in conditions:
            t = times.loc[(condition, source)]
            cell = _mean_sd(t["mean"], t["sd"])
            table.setdefault(f"{source} learning time (epochs)", {})[condition] = (
                cell if cell == "—" else f"{cell} (n={int(t['n'])})")
    curious, random = (paper.SYNTHETIC_CURIOUS, paper.SYNTHETIC_RANDOM) if spec == SYNTHETIC else ({}, {})
    out = pd.DataFrame(
        [{"paper": _paper_cell(curious, label), "paper (random)": _paper_cell(random, label), **cells}
         for label, cells in table.items()],
        index=pd.Index(list(table), name="outcome"),
    )
    return out[["paper", "paper (random)", *conditions]]


def _json_safe(value):
    """Plain Python values for json.dumps; NaN and ±inf become None."""
    if isinstance(value, Mapping):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    return value


def summary(
    episodes: pd.DataFrame,
    modules: pd.DataFrame,
    spec: SourceSpec = SYNTHETIC,
    *,
    reference: str = "curious",
) -> dict:
    """A JSON-serialisable summary of a results folder (written as ``summary.json``).

    Keys: ``n_runs`` (per condition), ``order_counts``, ``metrics`` (mean/sd per condition),
    ``learning_time`` (epochs per learnable source), ``comparisons`` (``reference`` against
    every other condition, when both exist). NaN and infinities are written as null.
    """
    require_order_columns(episodes, modules, needed_by="summary")
    require_learning_columns(episodes, modules, needed_by="summary")
    runs = per_run(episodes, modules, spec)
    conditions = sorted(runs["condition"].unique())
    comparisons = []
    if reference in conditions:
        comparisons = [compare(runs, reference, other, spec=spec) for other in conditions if other != reference]
    result = {
        "n_runs": runs.groupby("condition").size().to_dict(),
        "order_counts": order_counts(episodes, modules, spec).to_dict("records"),
        "metrics": condition_summary(episodes, modules, spec).to_dict("records"),
        "learning_time": learning_time_summary(episodes, modules, spec).to_dict("records"),
        "comparisons": pd.concat(comparisons).to_dict("records") if comparisons else [],
    }
    return _json_safe(result)
