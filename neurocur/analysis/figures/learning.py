"""Seaborn figures of module learning in a results folder (paper Figures 4D, 4F and the storage order).

The estimation error falling within each learning cycle (Figure 4D), the learning time of
each source (Figure 4F) and which source was stored first, second, third (section 4.1.4).
Every function returns a :class:`matplotlib.figure.Figure` in the style of
:mod:`neurocur.analysis.figures.style`; :func:`~neurocur.analysis.figures.sets.write_all` saves
them as PNG. Each checks on entry
that its tables have the columns it reads (:func:`neurocur.contract.require_columns`), so
a table without, say, a module table's columns gives an error naming them and the role producing
them. The reward and neuromodulator figures of a run (Figures 4E, 4G) are in
:mod:`~neurocur.analysis.figures.reward`, which shares this module's choice of condition and run.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, MaxNLocator

from neurocur.analysis import paper
from neurocur.analysis.results import Results
from neurocur.analysis.stats.bootstrap import bootstrap_ci
from neurocur.analysis.stats.cycles import error_cycles
from neurocur.analysis.stats.learning_time import learning_time_summary, learning_times, require_learning_columns
from neurocur.analysis.stats.order import position_counts, require_order_columns
from neurocur.analysis.stats.report import of_the_paper
from neurocur.analysis.stats.verdict import paper_range
from neurocur.contexts.base import SourceSpec
from neurocur.contract import require_columns

from .layout import panel_grid
from .style import caption, condition_colours, figure, source_colours, style

__all__ = [
    "condition_of",
    "fig_cumulative_error",
    "fig_learning_time",
    "fig_order_counts",
]

#: The y label of :func:`fig_cumulative_error` for the ``error`` column (eq 11 / M).
CUMULATIVE_ERROR = "cumulative error ξ / M (eq 11)"
#: gid of the vertical lines marking module storage, so they can be told from data lines.
EVENT_GID = "module_learned"
#: gid of the marks of the paper's numbers (Luciw et al. 2013), so they can be told from the model's.
PAPER_GID = "paper"
#: Frames in thousands on a step axis: "150k".
KILO_FRAMES = FuncFormatter(lambda v, _: f"{v / 1000:g}k".replace("-", "−"))


def condition_of(table: pd.DataFrame, condition: str | None) -> str:
    """``condition``, checked to be in ``table``; by default the table's first condition in name order.

    Parameters
    ----------
    table : pandas.DataFrame
        A table with a ``condition`` column (the episodes table, or another of the folder's tables).
    condition : str or None
        The condition asked for; None for the table's first condition in name order.

    Returns
    -------
    str
        The condition.

    Raises
    ------
    ValueError
        When the table is empty, or ``condition`` is not one of its conditions (the message lists them).
    """
    conditions = sorted(table["condition"].unique())
    if not conditions:
        raise ValueError("the episodes table is empty")
    if condition is None:
        return conditions[0]
    if condition not in conditions:
        raise ValueError(f"condition {condition!r} not in the results; have {conditions}")
    return condition


def one_run(episodes: pd.DataFrame, condition: str | None, run: int | None) -> tuple[str, int, pd.DataFrame]:
    """One run's episodes in episode order: ``run`` of ``condition`` (:func:`condition_of`).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table (columns ``condition``, ``run``, ``episode``).
    condition : str or None
        The condition; None for the first in name order.
    run : int or None
        The run; None for the condition's lowest-numbered run.

    Returns
    -------
    condition : str
        The condition.
    run : int
        The run.
    table : pandas.DataFrame
        The run's rows of ``episodes``, sorted by ``episode``.

    Raises
    ------
    ValueError
        When the condition or the run is not in the table.
    """
    condition = condition_of(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    runs = sorted(table["run"].unique())
    if run is None:
        run = runs[0]
    if run not in runs:
        raise ValueError(f"run {run} not in condition {condition!r}; have runs {runs}")
    return condition, int(run), table[table["run"] == run].sort_values("episode")


def fig_cumulative_error(
    episodes: pd.DataFrame,
    condition: str | None = None,
    run: int | None = None,
    *,
    column: str = "error",
    bin_steps: int = 1000,
    max_cycles: int | None = 3,
    min_runs: int = 3,
    spec: SourceSpec | None = None,
    threshold: float | None = None,
) -> Figure:
    """Figure 4D: the estimation error falling within each learning cycle.

    The paper's "cumulative estimation error" is eq 11's context-wide error ξ, accumulated over
    the context's states, drawn per state (ξ / M: column ``error``, the mean of the stored eq-10
    errors) as the figure's title and axis say; not a running sum over time. Both panels have a
    log error axis, on which the fall to the freeze ``threshold`` (drawn when given) shows.
    Left: one run (``run``, default the first) per episode against the global step, each
    module storage marked (dashed, gid ``"module_learned"``). Right: the error aligned to the
    storage that ends each learning cycle
    (:func:`~neurocur.analysis.stats.cycles.error_cycles`: per run, the mean over bins of
    ``bin_steps`` frames before storage), the mean over runs with its 95 % percentile bootstrap
    interval over runs (:func:`~neurocur.analysis.stats.bootstrap.bootstrap_ci`, Efron & Tibshirani
    1993), where at least ``min_runs`` runs had the bin. With the world's ``spec``: one line per
    stored source, the error of the module being learned on the contexts of that source only (the
    other contexts, visited between, hide its fall), in the source's colour
    (:func:`~neurocur.analysis.figures.style.source_colours`); without: one line per cycle (the
    first ``max_cycles``), over every episode. The legend stands outside the data.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table (columns ``condition``, ``run``, ``episode``, ``step``, ``n_frames``,
        ``module_learned`` and ``column``).
    condition : str or None
        The condition drawn; None for the first in name order (``condition_of``).
    run : int or None
        The run of the left panel; None for the condition's lowest-numbered run.
    column : str
        The error column drawn: ``error`` (eq 11 / M, labelled so), or another column, labelled by its name.
    bin_steps : int
        Frames per bin of the right panel's curves.
    max_cycles : int or None
        Without ``spec``: the cycles drawn, the first ones; None for every cycle. Unused with ``spec``.
    min_runs : int
        The fewest runs a bin must have to be drawn on the right panel.
    spec : SourceSpec or None
        The world's sources (``Results.spec_of``): one line per stored source, on its contexts; None for one
        line per cycle, over every episode.
    threshold : float or None
        The freeze threshold (the HPC's ``threshold``), drawn dotted on both panels; None draws none.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels sharing the log error axis: the run (left), the cycles (right).
    """
    require_columns(episodes, ["condition", "run", "episode", "step", "n_frames", "module_learned", column],
                    needed_by="fig_cumulative_error")
    condition = condition_of(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    _, run, single = one_run(episodes, condition, run)
    by_source = spec is not None
    cycles = error_cycles(table, column, bin_steps, context_sources=spec.context_sources if by_source else None)
    if max_cycles is not None and not by_source:
        cycles = cycles[cycles["cycle"] <= max_cycles]
    group = "source" if by_source else "cycle"
    cycles = cycles[cycles.groupby([group, "bin"])["run"].transform("nunique") >= min_runs]
    ylabel = CUMULATIVE_ERROR if column == "error" else column
    with style():
        fig, axes = figure(1, 2, figsize=(12.0, 4.4), sharey=True)
        fig.suptitle("Figure 4D. Cumulative estimation error: eq 11, the context's error summed over its states "
                     "(here per state);\nnot a running sum over time", fontsize="medium")
        left, right = axes[0]
        left.plot(single["step"], single[column], lw=0.6, color="0.3", label=f"run {run}")
        for x in (single["step"] + single["n_frames"])[single["module_learned"].astype(bool)]:
            left.axvline(x, color="0.3", ls="--", lw=0.8, gid=EVENT_GID)
        left.set(xlabel="global step (frames)", ylabel=ylabel, title=f"{condition}, run {run}: every episode")
        if by_source:
            colours = source_colours([*spec.context_sources, *cycles["source"]])
            lines = [(source, colours[source], f"{source}'s module ({part['run'].nunique()} runs)", part)
                     for source, part in cycles.groupby("source", sort=False)]
            lines.sort(key=lambda line: [*spec.context_sources, line[0]].index(line[0]))
        else:
            palette = sns.color_palette("Greys_r", max(1, cycles["cycle"].nunique()) + 2)
            lines = [(cycle, palette[k], f"module {cycle}", part)
                     for k, (cycle, part) in enumerate(cycles.groupby("cycle", sort=True))]
        for _, colour, label, part in lines:
            bins = part.groupby(-part["frames_before"], sort=True)[column]      # x: frames from storage, ≤ 0
            means = bins.mean()
            ci = np.array([bootstrap_ci(values.to_numpy()) for _, values in bins])
            right.plot(means.index, means.to_numpy(), color=colour, label=label)
            right.fill_between(means.index, ci[:, 0], ci[:, 1], color=colour, alpha=0.2, lw=0)
        if threshold is not None:
            for ax in (left, right):
                ax.axhline(threshold, color="0.5", ls=":", lw=1.0, label=f"freeze threshold {threshold:g}")
        for ax in (left, right):
            ax.set_yscale("log", nonpositive="mask")
        if cycles.empty:
            right.text(0.5, 0.5, f"no cycle in {min_runs} or more runs", ha="center", va="center",
                       transform=right.transAxes)
        right.axvline(0.0, color="0.3", ls="--", lw=0.8, gid=EVENT_GID)
        what = "on the stored source's contexts" if by_source else "every episode"
        right.set(xlabel="frames before the module's storage (dashed)", ylabel=ylabel,
                  title=f"Per cycle, aligned to storage: {what}")
        for ax in (left, right):
            ax.xaxis.set_major_formatter(KILO_FRAMES)
        if right.get_legend_handles_labels()[1]:
            right.legend(title=f"{table['run'].nunique()} runs; mean, 95 % CI; ≥ {min_runs} runs a bin",
                         loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small")
    return caption(fig, "Figure 4D (section 4.1.4)",
                   f"{condition}: the estimation error (eq 11 / M) of one run, and per learning cycle the error "
                   f"{'of the module being learned on its source' if by_source else 'of every episode'}, "
                   "aligned to the storage that ends the cycle (log axis)")


def fig_learning_time(results: Results, condition: str | None = None, *, since: str = "previous") -> Figure:
    """Figure 4F: learning time per learnable source in epochs, mean ± sd over the runs that learned
    it, the statistic of the order table: the bars are
    :func:`~neurocur.analysis.stats.learning_time.learning_time_summary`, the runs drawn as points
    (learning times are skewed: a source learned late in a run can take ten times the median).

    One bar per (source, condition) — all conditions unless ``condition`` is given — in the
    condition's colour (:func:`~neurocur.analysis.figures.style.condition_colours`). Learning time
    as in :func:`neurocur.analysis.stats.learning_time.learning_times` (first module of each source).
    For the paper's experiment (:func:`~neurocur.analysis.stats.report.of_the_paper`) the paper's
    values (section 4.1.1: S-A 2–3, S-B ≈15, S-C ≈40 epochs,
    :data:`~neurocur.analysis.paper.SYNTHETIC_CURIOUS`) are drawn over each source's bars in black
    (gid ``"paper"``): a diamond at a value, a bar over a range.

    Parameters
    ----------
    results : Results
        A results folder's tables (``neurocur.analysis.results.Results``).
    condition : str or None
        The one condition drawn; None for every condition of ``results``, in its order.
    since : str
        ``"previous"`` or ``"start"``: where a module's count of frames begins
        (``neurocur.analysis.stats.learning_time.learning_times``).

    Returns
    -------
    matplotlib.figure.Figure
        One axes: a group of bars per learnable source.
    """
    require_learning_columns(results.episodes, results.modules, needed_by="fig_learning_time")
    times = learning_times(results, since=since)
    times = times[times["learnable"] & times["first_of_source"]]
    conditions = results.conditions
    colours = condition_colours(conditions)
    if condition is not None:
        conditions = [condition_of(results.episodes, condition)]
    learnable = list(dict.fromkeys(s for c in conditions for s in results.spec_of(c).learnable))
    summary = learning_time_summary(results.select(conditions), since=since).set_index(["condition", "source"])
    width = 0.8 / len(conditions)
    rng = np.random.default_rng(0)  # the points' horizontal jitter only
    with style():
        fig, axes = figure(figsize=(7.5, 4.2))
        ax = axes[0, 0]
        for k, name in enumerate(conditions):
            for x, source in enumerate(learnable):
                if (name, source) not in summary.index or not summary.loc[(name, source), "n"]:
                    continue
                row = summary.loc[(name, source)]
                centre = x - 0.4 + width * (k + 0.5)
                ax.bar(centre, row["mean"], width, color=colours[name], alpha=0.75,
                       label=None if name in ax.get_legend_handles_labels()[1] else name,
                       yerr=None if np.isnan(row["sd"]) else row["sd"], capsize=3)
                runs = times.loc[(times["condition"] == name) & (times["source"] == source), "epochs"]
                ax.scatter(centre + rng.uniform(-0.2, 0.2, len(runs)) * width, runs, color="0.2", s=9, zorder=3)
        if of_the_paper(results.select(conditions)):
            _paper_learning_times(ax, learnable)
        if times[times["condition"].isin(conditions)].empty:
            ax.text(0.5, 0.5, "no learnable source was learned", ha="center", va="center", transform=ax.transAxes)
        else:
            handles, labels = ax.get_legend_handles_labels()
            order = sorted(range(len(labels)), key=lambda i: labels[i] not in conditions)  # the paper last
            ax.legend([handles[i] for i in order], [labels[i] for i in order], title="condition", fontsize="small",
                      loc="upper left", bbox_to_anchor=(1.02, 1.0))
        ax.set(xticks=range(len(learnable)), xticklabels=learnable, xlabel="source", ylabel="learning time (epochs)",
               title="Figure 4F. Learning time per source\n(mean ± sd over the runs that learned it; points: runs)")
    return caption(fig, "Figure 4F (sections 4.1.1, 4.1.4)",
                   "learning time per learnable source in epochs, mean ± sd per condition, each run a point; "
                   "black: the paper's values (S-A 2–3, S-B ≈15, S-C ≈40 epochs)")


def _paper_learning_times(ax, sources) -> None:
    """The paper's learning time of each of ``sources`` (section 4.1.1) over its bars, labelled once."""
    label = "paper (section 4.1.1)"
    for x, source in enumerate(sources):
        reported = paper.SYNTHETIC_CURIOUS.get(f"{source} learning time (epochs)")
        if reported is None:
            continue
        low, high, _ = paper_range(reported.value)
        beside = x + 0.46                                  # right of the source's bars
        if high > low:
            ax.plot([beside, beside], [low, high], color="black", lw=4, solid_capstyle="butt", gid=PAPER_GID,
                    label=label)
        else:
            ax.plot([beside], [low], marker="D", ms=7, color="black", mec="white", ls="none", gid=PAPER_GID,
                    label=label)
        ax.annotate(f"paper {reported.value}", (beside, high), xytext=(0, 6), textcoords="offset points",
                    ha="center", va="bottom", fontsize="small")
        label = None


def fig_order_counts(results: Results, *, wrap: int = 4, marks: Mapping[str, Mapping[int, float]] | None = None,
                     note: str | None = None) -> Figure:
    """Which source was stored 1st/2nd/3rd, counted over runs (runs without any module count
    as "none"); the count axis is in whole runs. Each source in its colour
    (:func:`~neurocur.analysis.figures.style.source_colours`), "none" white with an outline.

    One panel per condition, laid out by the swept parameters of a sweep
    (:func:`~neurocur.analysis.stats.sweeps.sweep_points`): a row per base condition, a column per
    sweep point (in the order of the swept values); without a sweep, the conditions in rows of
    at most ``wrap`` panels. For the paper's experiment
    (:func:`~neurocur.analysis.stats.report.of_the_paper`) each panel marks the paper's counts of
    its curious agent (section 4.1.4: S-A first 25/25, S-B second 18/25, S-C third 18/25), scaled
    to the panel's runs, with black diamonds (gid ``"paper"``) on their bars; ``marks`` gives other
    shares to mark (``{source or "none": {position: share of runs}}``) and ``note`` says what they are.

    Parameters
    ----------
    results : Results
        A results folder's tables (``neurocur.analysis.results.Results``).
    wrap : int
        Panels per row when the conditions are not a sweep.
    marks : mapping of str to mapping of int to float, or None
        Shares of runs to mark with diamonds, ``{source or "none": {position: share}}`` (1-based
        positions), each scaled to its panel's runs; None marks the paper's counts for the paper's
        experiment and nothing otherwise; an empty mapping marks nothing.
    note : str or None
        The figure's title, saying what ``marks`` are; None for none. Replaced when ``marks`` is None.

    Returns
    -------
    matplotlib.figure.Figure
        A panel per condition; bars per storage position and source.
    """
    require_order_columns(results.episodes, results.modules, needed_by="fig_order_counts")
    counts = position_counts(results)
    grid = panel_grid(results.episodes, sorted(counts["condition"].unique()), wrap)
    sources = list(dict.fromkeys(counts["source"]))
    colours = {**source_colours([s for s in sources if s != "none"]), "none": "white"}
    if marks is None:
        marks = _paper_positions(results) if of_the_paper(results) else {}
        note = ("Module order (section 4.1.4). ◆ the paper's curious agent: S-A first 25/25, S-B second 18/25, "
                "S-C third 18/25; exact order 18/25 (implied)") if marks else None
    width = 0.8 / len(sources)
    nrows, ncols = len(grid), max(len(row) for row in grid)
    with style():
        fig, axes = figure(nrows, ncols, figsize=(3.6 * ncols + 2.2, 3.2 * nrows + 0.4), sharey=True)
        for i, row in enumerate(grid):
            for j in range(ncols):
                ax = axes[i, j]
                if j >= len(row) or row[j] is None:
                    ax.set_visible(False)
                    continue
                table = counts[counts["condition"] == row[j]]
                n = int(table["n"].iloc[0])
                for k, source in enumerate(sources):
                    part = table[table["source"] == source]
                    x = part["position"].to_numpy() - 0.4 + width * (k + 0.5)
                    ax.bar(x, part["k"].to_numpy(), width, color=colours[source], edgecolor="0.3", lw=0.6,
                           label=source)
                    for position, share in marks.get(source, {}).items():
                        ax.plot([position - 0.4 + width * (k + 0.5)], [share * n], marker="D", ms=7, color="black",
                                mec="white", ls="none", gid=PAPER_GID, label="paper's count, scaled to n")
                ax.yaxis.set_major_locator(MaxNLocator(integer=True))
                ax.set(xticks=sorted(table["position"].unique()), xlabel="storage position", ylabel="runs",
                       title=f"{row[j]} (n={n})")
        handles, labels = axes[0, 0].get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        axes[0, len(grid[0]) - 1].legend(unique.values(), unique.keys(), title="source", loc="upper left",
                                         bbox_to_anchor=(1.02, 1.0), fontsize="small")
        if note:
            fig.suptitle(note, fontsize="medium")
    what = "which source each run stored first, second, third, per condition"
    if not marks:
        return caption(fig, "none", what)
    return caption(fig, "none: section 4.1.4's counts (S-A first 25/25, S-B second 18/25, S-C third 18/25)",
                   f"{what}; diamonds: the paper's counts scaled to the runs")


def _paper_positions(results: Results) -> dict[str, dict[int, float]]:
    """The paper's share of runs storing each source at each position (section 4.1.4), by source:
    {"S-A": {1: 1.0}, "S-B": {2: 0.72}, "S-C": {3: 0.72}}, read from the order table's rows
    "<source> <ordinal>" of :data:`~neurocur.analysis.paper.SYNTHETIC_CURIOUS`."""
    marks: dict[str, dict[int, float]] = {}
    for k, source in enumerate(results.spec.learnable):
        for label, reported in paper.SYNTHETIC_CURIOUS.items():
            if label.startswith(f"{source} ") and label.split(" ", 1)[1] in _ORDINAL_WORDS[k:k + 1]:
                marks.setdefault(source, {})[k + 1] = paper_range(reported.value)[0]
    return marks


_ORDINAL_WORDS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth")
