"""The order table of a results folder beside the paper's numbers, and its paired tests (the summary,
``summary.json``, is :mod:`~neurocur.analysis.stats.folder_summary`).

The table and its tests gather the statistics of :mod:`~neurocur.analysis.stats.order`,
:mod:`~neurocur.analysis.stats.learning_time`, :mod:`~neurocur.analysis.stats.efficiency` and
:mod:`~neurocur.analysis.stats.comparison`;
:func:`order_table` sets the paper's numbers (:mod:`~neurocur.analysis.paper`) beside them.
Every p-value it shows is named by its test (paired by run: Wilcoxon 1945 signed-rank,
McNemar 1947 exact) and its multiple-comparison adjustment (Holm 1979 by default, or
Benjamini & Hochberg 1995).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import pandas as pd

from neurocur.analysis import paper
from neurocur.analysis.results import Results
from neurocur.contexts.base import SourceSpec
from neurocur.contexts.synthetic import SYNTHETIC

from .bootstrap import BOOTSTRAP_SEED, N_BOOT
from .comparison import ADJUSTMENT_NAMES, COMPARE_COLUMNS, compare_conditions
from .degenerate import degenerate_conditions
from .efficiency import EFFICIENCY_LABELS, EFFICIENCY_TESTS, censoring_horizon, efficiency_per_run
from .learning_time import learning_time_summary, require_learning_columns
from .order import condition_summary, order_counts, outcome_labels, per_run, require_order_columns
from .significance import TESTS

__all__ = ["TABLE_TESTS", "DEGENERATE_NOTE", "order_table", "of_the_paper", "comparison_rows", "family_note", "paired_tests",
           "reference_group", "paired_test_rows"]

#: The per-run metrics whose paired test against the reference condition the order table shows.
TABLE_TESTS = ("exact_order", "gated_sources")
#: The order table's row that names the degenerate conditions left out of its tests.
DEGENERATE_NOTE = "left out of the tests: its runs repeat another condition's, run for run"
_NUMERIC_LABELS = {"n_modules": "modules per run", "n_learned": "learnable sources learned",
                   "gated_sources": "learnable sources gated", "kendall_tau": "Kendall τ vs Ω"}


def _mean_sd(mean: float, sd: float) -> str:
    if math.isnan(mean):
        return "—"
    return f"{mean:.2f}" if math.isnan(sd) else f"{mean:.2f} ± {sd:.2f}"


def _frames(value: float) -> str:
    return "—" if math.isnan(value) else f"{value / 1000:.1f}k"


def _efficiency_labels(spec: SourceSpec, horizon: float | None = None) -> dict[str, str]:
    labels = dict(EFFICIENCY_LABELS)
    if horizon is not None:
        labels["frames_to_learn_all_censored"] = f"frames to learn all (censored at {_frames(horizon)} frames, the shortest run)"
    if spec.unlearnable:
        labels["frames_unlearnable"] += f" ({'/'.join(spec.unlearnable)})"
    return labels


def _efficiency_cells(runs: pd.DataFrame, spec: SourceSpec) -> dict[str, str]:
    """The order table's efficiency cells of one condition's :func:`efficiency_per_run` rows, by label."""
    labels = _efficiency_labels(spec, runs["horizon"].iloc[0] if len(runs) else None)
    did = runs["frames_to_learn_all"].dropna()
    censored, unlearnable = runs["frames_to_learn_all_censored"], runs["frames_unlearnable"].astype(float)
    return {
        labels["learned_all"]: f"{int(runs['learned_all'].sum())}/{len(runs)}",
        f"{labels['frames_to_learn_all']}: median (range)": (
            f"{_frames(did.median())} ({_frames(did.min())}–{_frames(did.max())}; n={len(did)})" if len(did) else "—"),
        f"{labels['frames_to_learn_all_censored']}: mean ± sd": (
            f"{_frames(censored.mean())} ± {_frames(censored.std())}" if len(runs) else "—"),
        f"{labels['frames_unlearnable']}: mean ± sd": (
            f"{_frames(unlearnable.mean())} ± {_frames(unlearnable.std())}" if len(runs) else "—"),
        labels["modules_per_1e5"]: _mean_sd(runs["modules_per_1e5"].mean(), runs["modules_per_1e5"].std()),
    }


def _paper_cell(numbers: Mapping[str, paper.Reported], label: str) -> str:
    reported = numbers.get(label)
    return "—" if reported is None else reported.cell()


def comparison_rows(tests: pd.DataFrame, conditions, reference: str, spec: SourceSpec,
                    horizon: float | None = None) -> pd.DataFrame:
    """The order table's test rows of one family ``tests`` (a
    :func:`~neurocur.analysis.stats.comparison.compare_conditions` table of ``reference`` against
    the others, e.g. a value of :func:`paired_tests`), one row per metric; ``spec``: the sources
    of their world and ``horizon`` the cut-off of the censored frames, which name the metrics.

    A row's label names the metric, the reference, the test and the adjustment, e.g.
    "learnable sources gated vs A: Wilcoxon signed-rank p (paired; Holm, 4 tests)";
    the family adjusted together is every p-value of ``tests``. A cell is the adjusted
    p-value with the pairs it rests on ("0.0023 (n=25)"; McNemar: "0.031 (7 of 25
    discordant)"); "—" for the reference and where nothing could be tested. Columns:
    ``conditions``. Empty when ``tests`` is.

    Parameters
    ----------
    tests : pandas.DataFrame
        One family of tests, with ``COMPARE_COLUMNS``.
    conditions : iterable of str
        The table's columns, in order.
    reference : str
        The condition the others were tested against.
    spec : SourceSpec
        The sources of the conditions' world.
    horizon : float, optional
        The cut-off of the censored frames, in the censored metric's label; None: not named.

    Returns
    -------
    pandas.DataFrame
        Text cells, indexed by ``outcome`` (the rows' labels).
    """
    conditions = list(conditions)
    if not len(tests):
        return pd.DataFrame(columns=conditions, dtype=object)
    labels = {**_NUMERIC_LABELS, **_efficiency_labels(spec, horizon), **outcome_labels(spec)}
    out: dict[str, dict[str, str]] = {}
    for metric, rows in tests.groupby("metric", sort=False):
        label = f"{labels.get(metric, metric)} vs {reference}: {TESTS[rows['method'].iloc[0]][0]} p ({family_note(rows)})"
        cells = dict.fromkeys(conditions, "—")
        for row in rows.itertuples(index=False):
            if math.isnan(row.p_adjusted):
                continue
            pairs = (f"{row.n_nonzero} of {row.n_pairs} discordant" if row.method == "mcnemar_exact"
                     else f"n={row.n_pairs}")
            cells[row.b] = f"{row.p_adjusted:.2g} ({pairs})"
        out[label] = cells
    return pd.DataFrame.from_dict(out, orient="index", columns=conditions).rename_axis("outcome")


def family_note(tests: pd.DataFrame) -> str:
    """How the p-values of ``tests`` (rows of a family) were adjusted, in words: the pairing, the
    adjustment and the family's size, e.g. "paired; Holm, 8 tests". The order table's rows and the
    efficiency figure's titles both say it so.

    Parameters
    ----------
    tests : pandas.DataFrame
        Rows of one adjusted family (``compare`` columns); the first row is read.

    Returns
    -------
    str
        The note.
    """
    row = tests.iloc[0]
    paired = "" if pd.isna(row["n_pairs"]) else "paired; "
    return f"{paired}{ADJUSTMENT_NAMES[row['adjustment']][0]}, {int(row['n_tests'])} tests"


def paired_tests(
    results: Results,
    reference: str,
    *,
    adjust: str | None = "holm",
    horizon: float | None = None,
    exclude_degenerate: bool = True,
    paired: bool = True,
    n_boot: int = N_BOOT,
    seed: int = BOOTSTRAP_SEED,
) -> dict[str, pd.DataFrame]:
    """The paired tests of ``reference`` against every other condition of ``results``, in two
    families each adjusted on its own: ``"efficiency"`` (:data:`~neurocur.analysis.stats.efficiency.EFFICIENCY_TESTS`,
    censored at ``horizon``, by default the shortest run of ``results``) and ``"order"``
    (:data:`TABLE_TESTS`); each a :func:`~neurocur.analysis.stats.comparison.compare_conditions`
    table, empty when there is nothing to compare. With ``exclude_degenerate`` (the default), a
    condition whose runs repeat another's (:func:`~neurocur.analysis.stats.degenerate.degenerate_conditions`)
    is left out of both. ``paired=False``: the unpaired tests
    (:func:`~neurocur.analysis.stats.comparison.compare`).

    The one computation of these p-values: the order table (:func:`paired_test_rows`), the
    summary and the efficiency figure (:func:`~neurocur.analysis.figures.neuro.fig_efficiency`)
    all read it, so that each shows the same adjusted p-value over the same family.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables.
    reference : str
        The condition tested against the others.
    adjust : str or None
        The adjustment of each family's p-values (``"holm"``, ``"bh"`` / ``"fdr_bh"``,
        ``"none"`` or None).
    horizon : float, optional
        The cut-off of the censored frames to learn all; None: the shortest run.
    exclude_degenerate : bool
        Leave the conditions whose runs repeat another's out of the tests.
    paired : bool
        Pair the runs by ``run`` (the default) or test them as independent samples.
    n_boot : int
        The bootstrap resamples of each interval.
    seed : int
        The bootstrap's seed.

    Returns
    -------
    dict of str to pandas.DataFrame
        ``{"efficiency": ..., "order": ...}``, each with ``COMPARE_COLUMNS``.
    """
    degenerate = degenerate_conditions(results) if exclude_degenerate else {}
    others = [c for c in results.conditions if c != reference and c not in degenerate]
    families = {"efficiency": (efficiency_per_run(results, horizon=horizon), list(EFFICIENCY_TESTS)),
                "order": (per_run(results), list(TABLE_TESTS))}
    return {name: (compare_conditions(runs, reference, others, metric=metrics, paired=paired, adjust=adjust,
                                      n_boot=n_boot, seed=seed)
                   if reference in results.conditions and others else pd.DataFrame(columns=COMPARE_COLUMNS))
            for name, (runs, metrics) in families.items()}


def reference_group(results: Results, reference: str) -> Results:
    """The conditions of ``results`` whose world shows the same sources as ``reference``'s: those
    :func:`paired_tests` compares with it (in the order table and the efficiency figure alike).

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables.
    reference : str
        One of its conditions.

    Returns
    -------
    neurocur.analysis.results.Results
        ``results`` restricted to those conditions (``reference`` among them).
    """
    return results.select([c for c, s in results.specs.items() if s == results.spec_of(reference)])


def paired_test_rows(
    results: Results,
    reference: str,
    *,
    adjust: str | None = "holm",
    horizon: float | None = None,
    exclude_degenerate: bool = True,
) -> pd.DataFrame:
    """The order table's test rows (:func:`comparison_rows`) of the two families of
    :func:`paired_tests` against ``reference``: the efficiency metrics, then the order metrics
    (:data:`TABLE_TESTS`). With ``exclude_degenerate`` (the default), a last row,
    :data:`DEGENERATE_NOTE`, names each left-out condition and the condition it repeats.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables, its conditions sharing one world's sources.
    reference : str
        The condition tested against the others.
    adjust : str or None
        The adjustment of each family's p-values (``"holm"``, ``"bh"`` / ``"fdr_bh"``,
        ``"none"`` or None).
    horizon : float, optional
        The cut-off of the censored frames to learn all; None: the shortest run.
    exclude_degenerate : bool
        Leave the conditions whose runs repeat another's out of the tests.

    Returns
    -------
    pandas.DataFrame
        Text cells, indexed by ``outcome``, one column per condition.
    """
    spec = results.spec
    horizon = censoring_horizon(results) if horizon is None else horizon
    families = paired_tests(results, reference, adjust=adjust, horizon=horizon, exclude_degenerate=exclude_degenerate)
    blocks = [comparison_rows(tests, results.conditions, reference, spec, horizon if name == "efficiency" else None)
              for name, tests in families.items()]
    degenerate = degenerate_conditions(results) if exclude_degenerate else {}
    if degenerate:
        note = {c: f"= {degenerate[c]}" if c in degenerate else "—" for c in results.conditions}
        blocks.append(pd.DataFrame([note], index=pd.Index([DEGENERATE_NOTE], name="outcome")))
    return pd.concat(blocks)


def order_table(
    results: Results,
    *,
    reference: str | None = None,
    adjust: str | None = "holm",
    horizon: float | None = None,
    exclude_degenerate: bool = True,
) -> pd.DataFrame:
    """The compact per-condition table printed by the CLI, beside the paper's numbers.

    Rows: the order outcomes ("k/n"), modules per run, learnable sources gated per run and
    Kendall τ (mean ± sd), the efficiency (:mod:`~neurocur.analysis.stats.efficiency`: runs that
    learned every learnable source, frames until then, frames in the unlearnable contexts,
    modules per 10⁵ frames), learning time per learnable source (epochs, mean ± sd); with a
    ``reference`` condition, then the paired tests against it (:func:`paired_test_rows`: the
    efficiency metrics, then :data:`TABLE_TESTS`; each row names its test and adjustment; a
    degenerate condition is left out of them unless ``exclude_degenerate`` is false, with a note). The
    frames to learn all of every condition and their test are censored at one cut-off, named in
    the rows: ``horizon``, by default the shortest run of ``results``
    (:func:`~neurocur.analysis.stats.efficiency.censoring_horizon`).
    The conditions must share one world's sources (:attr:`~neurocur.analysis.results.Results.spec`).
    Columns: "paper" (curious agent, :data:`~neurocur.analysis.paper.SYNTHETIC_CURIOUS`),
    "paper (random)" (:data:`~neurocur.analysis.paper.SYNTHETIC_RANDOM`), then one column
    per condition. The paper columns are there only for the paper's experiments: the synthetic
    world in one of :data:`~neurocur.analysis.paper.EXPERIMENTS` (by the ``name`` of the folder's
    ``config.toml``; tables in memory: the synthetic world).

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables, its conditions sharing one world's sources.
    reference : str, optional
        The condition the others are tested against; None: no test rows.
    adjust : str or None
        The adjustment of each family's p-values (``"holm"``, ``"bh"`` / ``"fdr_bh"``,
        ``"none"`` or None).
    horizon : float, optional
        The cut-off of the censored frames to learn all; None: the shortest run.
    exclude_degenerate : bool
        Leave the conditions whose runs repeat another's out of the tests.

    Returns
    -------
    pandas.DataFrame
        Text cells, indexed by ``outcome``.

    Raises
    ------
    ValueError
        When a column is missing or the conditions' worlds differ.
    """
    require_order_columns(results.episodes, results.modules, needed_by="order_table")
    require_learning_columns(results.episodes, results.modules, needed_by="order_table")
    spec = results.spec
    counts = order_counts(results)
    means = condition_summary(results).set_index(["condition", "metric"])
    times = learning_time_summary(results).set_index(["condition", "source"])
    conditions = results.conditions
    horizon = censoring_horizon(results) if horizon is None else horizon
    table: dict[str, dict[str, str]] = {}
    for row in counts.itertuples(index=False):
        table.setdefault(row.outcome, {})[row.condition] = f"{row.k}/{row.n}"
    for metric, label in (("n_modules", "modules per run"), ("gated_sources", "learnable sources gated"),
                          ("kendall_tau", "Kendall τ vs Ω")):
        for condition in conditions:
            m = means.loc[(condition, metric)]
            table.setdefault(label, {})[condition] = _mean_sd(m["mean"], m["sd"])
    efficiency = efficiency_per_run(results, horizon=horizon)
    for condition in conditions:
        for label, cell in _efficiency_cells(efficiency[efficiency["condition"] == condition], spec).items():
            table.setdefault(label, {})[condition] = cell
    for source in spec.learnable:
        for condition in conditions:
            t = times.loc[(condition, source)]
            cell = _mean_sd(t["mean"], t["sd"])
            table.setdefault(f"{source} learning time (epochs)", {})[condition] = (
                cell if cell == "—" else f"{cell} (n={int(t['n'])})")
    if reference is not None:
        table.update(paired_test_rows(results, reference, adjust=adjust, horizon=horizon,
                                      exclude_degenerate=exclude_degenerate).to_dict("index"))
    papers = {"paper": paper.SYNTHETIC_CURIOUS, "paper (random)": paper.SYNTHETIC_RANDOM} if of_the_paper(results) else {}
    out = pd.DataFrame(
        [{**{column: _paper_cell(numbers, label) for column, numbers in papers.items()}, **cells}
         for label, cells in table.items()],
        index=pd.Index(list(table), name="outcome"),
    )
    return out[[*papers, *conditions]]


def of_the_paper(results: Results) -> bool:
    """Whether ``results`` are the paper's synthetic experiment: its world, and one of
    :data:`~neurocur.analysis.paper.EXPERIMENTS` (or no recorded experiment name: tables in memory).

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables.

    Returns
    -------
    bool
        True for the paper's synthetic experiment.
    """
    return results.spec == SYNTHETIC and results.config.get("name") in (None, *paper.EXPERIMENTS)
