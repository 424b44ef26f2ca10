"""In which order the sources were learned: per-run order outcomes and their counts.

Every function takes a :class:`~neurocur.analysis.results.Results` (the tidy episodes and modules
tables and each condition's sources) and returns a tidy DataFrame (one observation per row),
except :func:`clopper_pearson` (a pair).

Definitions (paper section 4.1.4, Figure 4F):

* **Order.** "The k-th module" is the k-th row of the modules table of a run in
  storage order (every stored module counts, whatever its source). "S-B second"
  means the second stored module's source is S-B. The *exact order* holds when
  the first stored modules are exactly the learnable sources in Ω order
  (S-A, S-B, S-C), so nothing else was stored before them.
* **Unlearnable stored.** Some module's source is a source that is not learnable
  (S-D in the synthetic world).
* **Gated sources.** Per run, the number of learnable sources ``s`` such that some
  module whose ``source`` is ``s`` lists, in its ``gates``, a context whose
  source is ``s`` (the runner's end-of-run gating test), i.e. a module that
  represents the source and is familiar with it.
* **Kendall τ.** Between the storage order of the learnable sources that were
  learned (each at its first module) and their Ω order (eq 15); NaN when fewer
  than two learnable sources were learned.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy import stats as sps

from neurocur.analysis.results import Results
from neurocur.contexts.base import SourceSpec
from neurocur.contract import require_columns

__all__ = ["clopper_pearson", "ordinal_columns", "outcome_labels", "per_run", "sweep_columns", "order_counts",
           "position_counts", "condition_summary"]

_ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth")

#: Module-order columns of :func:`per_run` that are yes/no outcomes.
BINARY_METRICS = ("exact_order", "unlearnable_stored")
#: Per-run numeric metrics of :func:`per_run`, summarised by :func:`condition_summary`.
NUMERIC_METRICS = ("n_modules", "n_learned", "gated_sources", "kendall_tau")

#: The columns the order statistics read: ``condition`` and ``run`` are added by the loader,
#: ``source`` and ``gates`` by the world's module report.
EPISODE_COLUMNS = ("condition", "run", "n_frames")
MODULE_COLUMNS = ("condition", "run", "module", "source", "gates")


def require_order_columns(episodes: pd.DataFrame, modules: pd.DataFrame, *, needed_by: str) -> None:
    """:func:`neurocur.contract.require_columns` for the columns :func:`per_run` reads."""
    require_columns(episodes, EPISODE_COLUMNS, needed_by=f"{needed_by} (episodes table)")
    require_columns(modules, MODULE_COLUMNS, needed_by=f"{needed_by} (modules table)")


def clopper_pearson(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper–Pearson) two-sided interval for a binomial proportion k/n.

    Returns ``(nan, nan)`` when ``n == 0``; the bounds are 0 and 1 at the edges.

    Parameters
    ----------
    k : int
        The successes.
    n : int
        The trials.
    confidence : float
        The interval's coverage.

    Returns
    -------
    (float, float)
        The interval's ends.
    """
    if not (0 <= k <= n) or int(k) != k or int(n) != n:
        raise ValueError(f"clopper_pearson expected integers 0 <= k <= n, got k={k}, n={n}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"clopper_pearson expected 0 < confidence < 1, got {confidence}")
    if n == 0:
        return (math.nan, math.nan)
    ci = sps.binomtest(int(k), int(n)).proportion_ci(confidence_level=confidence, method="exact")
    return (float(ci.low), float(ci.high))


def ordinal_columns(runs: pd.DataFrame) -> list[str]:
    """The yes/no columns ``first_ok``, ``second_ok``, ... of a :func:`per_run` table, one per learnable source.

    Parameters
    ----------
    runs : pandas.DataFrame
        A :func:`per_run` table.

    Returns
    -------
    list of str
        The column names, in order.
    """
    return [f"{o}_ok" for o in _ORDINALS if f"{o}_ok" in runs]


def outcome_labels(spec: SourceSpec) -> dict[str, str]:
    """The row label of each yes/no column of :func:`per_run` ("S-A first", "exact S-A→S-B→S-C", "S-D stored").

    Parameters
    ----------
    spec : SourceSpec
        The world's sources (:class:`~neurocur.contexts.base.SourceSpec`).

    Returns
    -------
    dict of str to str
        By column.
    """
    labels = {f"{_ORDINALS[k]}_ok": f"{s} {_ORDINALS[k]}" for k, s in enumerate(spec.learnable)}
    labels["exact_order"] = "exact " + "→".join(spec.learnable)
    if spec.unlearnable:
        labels["unlearnable_stored"] = "/".join(spec.unlearnable) + " stored"
    return labels


def _run_row(order: list[str], gates: list[str], spec: SourceSpec) -> dict:
    n = len(spec.learnable)
    if n > len(_ORDINALS):
        raise ValueError(f"the order statistics support at most {len(_ORDINALS)} learnable sources")
    row = {"n_modules": len(order), "order": ",".join(order)}
    for k in range(n):
        row[_ORDINALS[k]] = order[k] if k < len(order) else ""
        row[f"{_ORDINALS[k]}_ok"] = k < len(order) and order[k] == spec.learnable[k]
    row["exact_order"] = tuple(order[:n]) == spec.learnable
    row["unlearnable_stored"] = any(s in spec.unlearnable for s in order)
    learned = [s for s in dict.fromkeys(order) if s in spec.learnable]
    row["n_learned"] = len(learned)
    gated = set()
    for source, gate in zip(order, gates):
        if source in spec.learnable and any(
            spec.source_of_name(name.strip()) == source for name in gate.split(",") if name.strip()
        ):
            gated.add(source)
    row["gated_sources"] = len(gated)
    if len(learned) >= 2:
        omega_rank = [spec.learnable.index(s) for s in learned]
        row["kendall_tau"] = float(sps.kendalltau(np.arange(len(learned)), omega_rank).statistic)
    else:
        row["kendall_tau"] = math.nan
    return row


def sweep_columns(table: pd.DataFrame) -> list[str]:
    """The swept-key columns of a results table (or of :func:`per_run`): the names with a dot.

    A sweep key is always ``"REGION.param"`` or ``"world.KEY"`` (the experiment file's
    ``[sweep]`` table) and the runner adds one column per swept key to every results table;
    no recorded column has a dot in its name.

    Parameters
    ----------
    table : pandas.DataFrame
        A results table.

    Returns
    -------
    list of str
        The column names, in order.
    """
    return [c for c in table.columns if isinstance(c, str) and "." in c]


def per_run(results: Results) -> pd.DataFrame:
    """One row per (condition, run) of ``results``: module order and the per-run metrics.

    Every run of the episodes table has a row, also a run that stored no module.
    Columns: condition, run, the swept keys of a sweep (:func:`sweep_columns`, the run's
    value; none without a sweep), n_steps, n_modules, order (stored sources, comma-separated),
    first/second/... (source of that module, "" if none), first_ok/second_ok/... (it is the
    learnable source of that Ω rank), exact_order, unlearnable_stored, n_learned (distinct
    learnable sources with a module), gated_sources, kendall_tau. See the module docstring.

    Parameters
    ----------
    results : Results
        A results folder's tables (:class:`~neurocur.analysis.results.Results`).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run).
    """
    episodes, modules = results.episodes, results.modules
    require_order_columns(episodes, modules, needed_by="per_run")
    steps = episodes.groupby(["condition", "run"])["n_frames"].sum()
    by_run = {key: g.sort_values("module") for key, g in modules.groupby(["condition", "run"])}
    rows = []
    for condition, run in steps.index:
        table = by_run.get((condition, run))
        order = [] if table is None else table["source"].astype(str).tolist()
        gates = [] if table is None else table["gates"].fillna("").astype(str).tolist()
        rows.append(
            {"condition": condition, "run": run, "n_steps": int(steps[(condition, run)]),
             **_run_row(order, gates, results.spec_of(condition))}
        )
    table = pd.DataFrame(rows)
    swept = sweep_columns(episodes)
    if swept and len(table):
        points = episodes.groupby(["condition", "run"])[swept].first().reset_index()
        table = points.merge(table, on=["condition", "run"], how="right")[
            ["condition", "run", *swept, *table.columns[2:]]]
    return table


def order_counts(results: Results, confidence: float = 0.95) -> pd.DataFrame:
    """Counts of the module-order outcomes per condition with Clopper–Pearson intervals.

    Columns: condition, outcome (e.g. "S-A first", "exact S-A→S-B→S-C", "S-D stored"),
    k, n (runs), proportion, ci_low, ci_high.

    Parameters
    ----------
    results : Results
        A results folder's tables (:class:`~neurocur.analysis.results.Results`).
    confidence : float
        The intervals' coverage.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, outcome).
    """
    require_order_columns(results.episodes, results.modules, needed_by="order_counts")
    runs = per_run(results)
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        n = len(table)
        for column, label in outcome_labels(results.spec_of(condition)).items():
            k = int(table[column].sum())
            low, high = clopper_pearson(k, n, confidence)
            rows.append({"condition": condition, "outcome": label, "k": k, "n": n,
                         "proportion": k / n, "ci_low": low, "ci_high": high})
    return pd.DataFrame(rows)


def position_counts(results: Results) -> pd.DataFrame:
    """How often each source was stored k-th (k = 1..number of learnable sources).

    Columns: condition, position (1-based), source, k (runs), n (runs of the condition).
    Every (condition, position, source) combination of the world's sources appears, with
    k = 0 where it never happened; "none" counts runs with fewer modules than the position.

    Parameters
    ----------
    results : Results
        A results folder's tables (:class:`~neurocur.analysis.results.Results`).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, position, source).
    """
    require_order_columns(results.episodes, results.modules, needed_by="position_counts")
    runs = per_run(results)
    spec = results.spec
    sources = list(dict.fromkeys([*spec.context_sources, *results.modules["source"]]))
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        for k in range(len(spec.learnable)):
            stored = table[_ORDINALS[k]].replace("", "none")
            for source in [*sources, "none"]:
                rows.append({"condition": condition, "position": k + 1, "source": source,
                             "k": int((stored == source).sum()), "n": len(table)})
    return pd.DataFrame(rows)


def condition_summary(results: Results) -> pd.DataFrame:
    """Mean and sd over runs of the per-run numeric metrics, per condition.

    Columns: condition, metric (n_modules, n_learned, gated_sources, kendall_tau), n (runs
    with a defined value), mean, sd (ddof=1; NaN for a single run).

    Parameters
    ----------
    results : Results
        A results folder's tables (:class:`~neurocur.analysis.results.Results`).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, metric).
    """
    require_order_columns(results.episodes, results.modules, needed_by="condition_summary")
    runs = per_run(results)
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        for metric in NUMERIC_METRICS:
            values = table[metric].astype(float).dropna()
            rows.append({"condition": condition, "metric": metric, "n": len(values),
                         "mean": values.mean() if len(values) else math.nan,
                         "sd": values.std(ddof=1) if len(values) > 1 else math.nan})
    return pd.DataFrame(rows)
