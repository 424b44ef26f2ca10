"""Statistics of a results folder: module order, gating, Kendall τ, learning time.

Every function takes the tidy ``episodes`` and ``modules`` tables of
:func:`neurocur.analysis.io.load` and returns a tidy DataFrame (one observation
per row), except :func:`clopper_pearson` (a pair) and :func:`summary` (a dict).

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
* **Learning time.** For a module stored at episode ``e_k``, the frames the agent
  spent in the contexts of the module's source during episodes
  ``e_{k-1} < episode <= e_k`` (``e_{k-1}``: the previous module's storage episode,
  or the start of the run for the first module; ``since="start"`` always counts from
  the start), divided by the epoch length (1000 frames). The adaptive module
  restarts at every storage, so this is the experience it took to learn the source.
  Figure 4F uses the first module of each learnable source.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from neurocur.contexts.base import SourceSpec
from neurocur.contexts.synthetic import SYNTHETIC

__all__ = [
    "SourceSpec",
    "SYNTHETIC",
    "clopper_pearson",
    "per_run",
    "order_counts",
    "position_counts",
    "condition_summary",
    "learning_times",
    "learning_time_summary",
    "compare",
    "order_table",
    "summary",
]

_ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth")


#: Module-order columns of :func:`per_run` that are yes/no outcomes.
_BINARY = ("exact_order", "unlearnable_stored")
#: Per-run numeric metrics summarised by :func:`condition_summary`.
_NUMERIC = ("n_modules", "n_learned", "gated_sources", "kendall_tau")


def clopper_pearson(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper–Pearson) two-sided interval for a binomial proportion k/n.

    Returns ``(nan, nan)`` when ``n == 0``; the bounds are 0 and 1 at the edges.
    """
    if not (0 <= k <= n) or int(k) != k or int(n) != n:
        raise ValueError(f"clopper_pearson expected integers 0 <= k <= n, got k={k}, n={n}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"clopper_pearson expected 0 < confidence < 1, got {confidence}")
    if n == 0:
        return (math.nan, math.nan)
    ci = sps.binomtest(int(k), int(n)).proportion_ci(confidence_level=confidence, method="exact")
    return (float(ci.low), float(ci.high))


def _check(episodes: pd.DataFrame, modules: pd.DataFrame, need_modules=("module", "source")):
    for name, table, cols in (
        ("episodes", episodes, ("condition", "run", "episode", "context", "n_frames")),
        ("modules", modules, ("condition", "run", *need_modules)),
    ):
        missing = [c for c in cols if c not in table]
        if missing:
            raise ValueError(f"{name} table lacks column(s) {missing} (see the results schema)")


def _ordinal_columns(spec: SourceSpec) -> list[str]:
    if len(spec.learnable) > len(_ORDINALS):
        raise ValueError(f"the order statistics support at most {len(_ORDINALS)} learnable sources")
    return [f"{_ORDINALS[k]}_ok" for k in range(len(spec.learnable))]


def _outcome_labels(spec: SourceSpec) -> dict[str, str]:
    labels = {f"{_ORDINALS[k]}_ok": f"{s} {_ORDINALS[k]}" for k, s in enumerate(spec.learnable)}
    labels["exact_order"] = "exact " + "→".join(spec.learnable)
    if spec.unlearnable:
        labels["unlearnable_stored"] = "/".join(spec.unlearnable) + " stored"
    return labels


def _runs(episodes: pd.DataFrame) -> pd.DataFrame:
    """The (condition, run) pairs of the episodes table: every run, even without modules."""
    return episodes[["condition", "run"]].drop_duplicates().sort_values(["condition", "run"])


def _run_row(order: list[str], gates: list[str], spec: SourceSpec) -> dict:
    n = len(spec.learnable)
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


def per_run(episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC) -> pd.DataFrame:
    """One row per (condition, run): module order and the per-run metrics.

    Columns: condition, run, n_steps, n_modules, order (stored sources, comma-separated),
    first/second/... (source of that module, "" if none), first_ok/second_ok/... (it is the
    learnable source of that Ω rank), exact_order, unlearnable_stored, n_learned (distinct
    learnable sources with a module), gated_sources, kendall_tau. See the module docstring.
    """
    _check(episodes, modules, need_modules=("module", "source", "gates"))
    steps = episodes.groupby(["condition", "run"])["n_frames"].sum()
    by_run = {key: g.sort_values("module") for key, g in modules.groupby(["condition", "run"])}
    rows = []
    for condition, run in _runs(episodes).itertuples(index=False):
        table = by_run.get((condition, run))
        order = [] if table is None else table["source"].astype(str).tolist()
        gates = [] if table is None else table["gates"].fillna("").astype(str).tolist()
        rows.append(
            {"condition": condition, "run": run, "n_steps": int(steps[(condition, run)]),
             **_run_row(order, gates, spec)}
        )
    return pd.DataFrame(rows)


def order_counts(
    episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC, confidence: float = 0.95
) -> pd.DataFrame:
    """Counts of the module-order outcomes per condition with Clopper–Pearson intervals.

    Columns: condition, outcome (e.g. "S-A first", "exact S-A→S-B→S-C", "S-D stored"),
    k, n (runs), proportion, ci_low, ci_high.
    """
    runs = per_run(episodes, modules, spec)
    labels = _outcome_labels(spec)
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        n = len(table)
        for column, label in labels.items():
            k = int(table[column].sum())
            low, high = clopper_pearson(k, n, confidence)
            rows.append({"condition": condition, "outcome": label, "k": k, "n": n,
                         "proportion": k / n, "ci_low": low, "ci_high": high})
    return pd.DataFrame(rows)


def position_counts(episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC) -> pd.DataFrame:
    """How often each source was stored k-th (k = 1..number of learnable sources).

    Columns: condition, position (1-based), source, k (runs), n (runs of the condition).
    Every (condition, position, source) combination of the world's sources appears, with
    k = 0 where it never happened; "none" counts runs with fewer modules than the position.
    """
    runs = per_run(episodes, modules, spec)
    sources = list(dict.fromkeys([*spec.context_sources, *modules.get("source", pd.Series(dtype=str))]))
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        for k in range(len(spec.learnable)):
            stored = table[_ORDINALS[k]].replace("", "none")
            for source in [*sources, "none"]:
                rows.append({"condition": condition, "position": k + 1, "source": source,
                             "k": int((stored == source).sum()), "n": len(table)})
    return pd.DataFrame(rows)


def condition_summary(episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC) -> pd.DataFrame:
    """Mean and sd over runs of the per-run numeric metrics, per condition.

    Columns: condition, metric (n_modules, n_learned, gated_sources, kendall_tau), n (runs
    with a defined value), mean, sd (ddof=1; NaN for a single run).
    """
    runs = per_run(episodes, modules, spec)
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        for metric in _NUMERIC:
            values = table[metric].astype(float).dropna()
            rows.append({"condition": condition, "metric": metric, "n": len(values),
                         "mean": values.mean() if len(values) else math.nan,
                         "sd": values.std(ddof=1) if len(values) > 1 else math.nan})
    return pd.DataFrame(rows)


def learning_times(
    episodes: pd.DataFrame,
    modules: pd.DataFrame,
    spec: SourceSpec = SYNTHETIC,
    *,
    since: str = "previous",
    epoch: int = 1000,
) -> pd.DataFrame:
    """Learning time of every stored module, in epochs (Figure 4F).

    ``since="previous"`` counts the frames spent in the contexts of the module's source
    after the previous module's storage episode (exclusive) up to this module's storage
    episode (inclusive); ``since="start"`` counts from the start of the run. Divided by
    ``epoch`` (1000 frames, one pass of a context's local clock).

    Columns: condition, run, module, source, episode, step, epochs, learnable,
    first_of_source (the first module of that source in the run). A module whose source
    drives no context has epochs NaN.
    """
    if since not in ("previous", "start"):
        raise ValueError(f"learning_times: since must be 'previous' or 'start', got {since!r}")
    if epoch <= 0:
        raise ValueError(f"learning_times: epoch must be a positive number of frames, got {epoch}")
    _check(episodes, modules, need_modules=("module", "source", "episode"))
    by_run = {key: g for key, g in episodes.groupby(["condition", "run"])}
    rows = []
    for (condition, run), table in modules.groupby(["condition", "run"], sort=True):
        eps = by_run.get((condition, run))
        if eps is None:
            raise ValueError(f"modules of condition {condition!r} run {run} have no episodes")
        ep, ctx, frames = (eps[c].to_numpy() for c in ("episode", "context", "n_frames"))
        previous, seen = -1, set()
        for module in table.sort_values("module").itertuples(index=False):
            contexts = spec.contexts_of(module.source)
            lower = previous if since == "previous" else -1
            window = (ep > lower) & (ep <= module.episode) & np.isin(ctx, contexts)
            rows.append({
                "condition": condition, "run": run, "module": module.module,
                "source": module.source, "episode": module.episode,
                "step": getattr(module, "step", math.nan),
                "epochs": frames[window].sum() / epoch if contexts else math.nan,
                "learnable": module.source in spec.learnable,
                "first_of_source": module.source not in seen,
            })
            seen.add(module.source)
            previous = module.episode
    columns = ["condition", "run", "module", "source", "episode", "step", "epochs",
               "learnable", "first_of_source"]
    return pd.DataFrame(rows, columns=columns)


def learning_time_summary(
    episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC, *, since: str = "previous"
) -> pd.DataFrame:
    """Mean ± sd learning time (epochs) per condition and learnable source (Figure 4F).

    Uses the first module of each learnable source in each run. Columns: condition, source,
    n (runs that learned it), mean, sd.
    """
    times = learning_times(episodes, modules, spec, since=since)
    times = times[times["learnable"] & times["first_of_source"]]
    rows = []
    for condition in sorted(episodes["condition"].unique()):
        for source in spec.learnable:
            values = times.loc[(times["condition"] == condition) & (times["source"] == source), "epochs"]
            rows.append({"condition": condition, "source": source, "n": len(values),
                         "mean": values.mean() if len(values) else math.nan,
                         "sd": values.std(ddof=1) if len(values) > 1 else math.nan})
    return pd.DataFrame(rows)


def _per_run_table(stats_or_tables, spec: SourceSpec) -> pd.DataFrame:
    if isinstance(stats_or_tables, pd.DataFrame):
        return stats_or_tables
    if isinstance(stats_or_tables, Sequence) and len(stats_or_tables) == 2:
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

    ``stats_or_tables`` is a :func:`per_run` table or an ``(episodes, modules)`` pair.
    ``metric`` defaults to every numeric and binary metric of :func:`per_run`.

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
        metrics = [*_NUMERIC, *_ordinal_columns(spec), *_BINARY]
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


#: The paper's numbers (section 4.1.4; "implied" = follows from the stated counts).
_PAPER = {
    "S-A first": "25/25",
    "S-B second": "18/25",
    "S-C third": "18/25",
    "exact S-A→S-B→S-C": "18/25 (implied)",
    "S-D stored": "0/25",
    "modules per run": "3 (implied)",
    "learnable sources gated": "3 (implied)",
    "Kendall τ vs Ω": "0.81 (implied)",
    "S-A learning time (epochs)": "2–3",
    "S-B learning time (epochs)": "≈15",
    "S-C learning time (epochs)": "≈40",
}
_PAPER_RANDOM = {"learnable sources gated": "0 (4.3: learns nothing)"}


def _mean_sd(mean: float, sd: float) -> str:
    if math.isnan(mean):
        return "—"
    return f"{mean:.2f}" if math.isnan(sd) else f"{mean:.2f} ± {sd:.2f}"


def order_table(episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec = SYNTHETIC) -> pd.DataFrame:
    """The compact per-condition table printed by the CLI, beside the paper's numbers.

    Rows: the order outcomes ("k/n"), modules per run, learnable sources gated per run and
    Kendall τ (mean ± sd), learning time per learnable source (epochs, mean ± sd).
    Columns: "paper" (curious agent, section 4.1.4), "paper (random)" (section 4.3), then
    one column per condition. The paper columns are filled only for the synthetic world.
    """
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
    paper = spec == SYNTHETIC
    out = pd.DataFrame(
        [{"paper": _PAPER.get(label, "—") if paper else "—",
          "paper (random)": _PAPER_RANDOM.get(label, "—") if paper else "—",
          **cells} for label, cells in table.items()],
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
