"""Seaborn figures of a results folder (paper Figures 4D–G and more).

Every function returns a :class:`matplotlib.figure.Figure` in the style of
:mod:`neurocur.analysis.figures.style`; :func:`~neurocur.analysis.figures.sets.write_all` saves
them as PNG. Each checks on entry
that its tables have the columns it reads (:func:`neurocur.contract.require_columns`), so
a table without, say, an LC's columns gives an error naming them and the role producing
them; a column that only some region models record (``epsilon``) is drawn when present.
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
from neurocur.config import ConfigError
from neurocur.contexts.base import SourceSpec
from neurocur.contract import require_columns
from neurocur.regions.pfc import PFCLSPI, SAMPLE_AVERAGE, PFCParams, eq14_rate, reward_update

from .layout import panel_grid, symlog_axis
from .style import caption, condition_colours, figure, source_colours, style

__all__ = [
    "condition_of",
    "fig_cumulative_error",
    "fig_intrinsic_reward",
    "fig_learning_time",
    "fig_reward_function",
    "fig_order_counts",
    "fig_neuromodulators",
    "reward_estimates",
]

#: The y label of :func:`fig_cumulative_error` for the ``error`` column (eq 11 / M).
CUMULATIVE_ERROR = "cumulative error ξ / M (eq 11)"
#: gid of the vertical lines marking module storage, so they can be told from data lines.
EVENT_GID = "module_learned"
#: gid of the marks of the paper's numbers (Luciw et al. 2013), so they can be told from the model's.
PAPER_GID = "paper"
#: Episodes in the running median drawn over a per-episode trace (:func:`fig_neuromodulators`).
TRACE_WINDOW = 25
#: Frames in thousands on a step axis: "150k".
KILO_FRAMES = FuncFormatter(lambda v, _: f"{v / 1000:g}k".replace("-", "−"))


def condition_of(table: pd.DataFrame, condition: str | None) -> str:
    """``condition``, checked to be in ``table``; by default the table's first condition in name order."""
    conditions = sorted(table["condition"].unique())
    if not conditions:
        raise ValueError("the episodes table is empty")
    if condition is None:
        return conditions[0]
    if condition not in conditions:
        raise ValueError(f"condition {condition!r} not in the results; have {conditions}")
    return condition


def _one_run(episodes: pd.DataFrame, condition: str | None, run: int | None) -> tuple[str, int, pd.DataFrame]:
    condition = condition_of(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    runs = sorted(table["run"].unique())
    if run is None:
        run = runs[0]
    if run not in runs:
        raise ValueError(f"run {run} not in condition {condition!r}; have runs {runs}")
    return condition, int(run), table[table["run"] == run].sort_values("episode")


def _binned(table: pd.DataFrame, column: str, bin_steps: int) -> pd.DataFrame:
    """Per-run mean of ``column`` over bins of ``bin_steps`` global steps (bin centre as step)."""
    if bin_steps <= 0:
        raise ValueError(f"bin_steps must be a positive number of frames, got {bin_steps}")
    binned = table.assign(step=table["step"] // bin_steps * bin_steps + bin_steps / 2)
    return binned.groupby(["run", "step"], as_index=False)[column].mean()


def _progress_linthresh(table: pd.DataFrame) -> float:
    """Linear range of a symlog DA axis: the 90th percentile of |DA| on unfamiliar episodes.

    Keeps the small learning-progress rewards readable beside the −100 boredom rewards.
    """
    progress = np.abs(table.loc[~table["familiar"].astype(bool), "da"].to_numpy(dtype=float))
    progress = progress[np.isfinite(progress) & (progress > 0)]
    return float(np.percentile(progress, 90)) if progress.size else 1.0


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
    """
    require_columns(episodes, ["condition", "run", "episode", "step", "n_frames", "module_learned", column],
                    needed_by="fig_cumulative_error")
    condition = condition_of(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    _, run, single = _one_run(episodes, condition, run)
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


def fig_intrinsic_reward(
    episodes: pd.DataFrame,
    condition: str | None = None,
    *,
    bin_steps: int = 1000,
    window: int = 5,
    include_boredom: bool = True,
    symlog: bool = True,
    ylim: tuple[float, float] | None = None,
) -> Figure:
    """Figure 4E: the run-averaged, smoothed intrinsic reward (DA) vs global step.

    DA is averaged per run over bins of ``bin_steps`` frames, averaged over runs, then
    smoothed by a centred moving average of ``window`` bins. The boredom reward (−100 on
    familiar episodes) is included as in the paper unless ``include_boredom=False`` (then
    familiar episodes are left out); ``symlog`` makes the y-axis linear only near zero
    (see :func:`fig_neuromodulators`) so the learning-progress rises show beside the boredom
    drops; ``ylim`` clips the y-axis (said in the title). One line (plus the zero line).
    """
    if window < 1:
        raise ValueError(f"window must be a positive number of bins, got {window}")
    require_columns(episodes, ["condition", "run", "step", "da", "familiar"], needed_by="fig_intrinsic_reward")
    condition = condition_of(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    if not include_boredom:
        table = table[~table["familiar"].astype(bool)]
    mean = _binned(table, "da", bin_steps).groupby("step")["da"].mean()
    smooth = mean.rolling(window, center=True, min_periods=1).mean()
    with style():
        fig, axes = figure()
        ax = axes[0, 0]
        colour = condition_colours(sorted(episodes["condition"].unique()))[condition]
        sns.lineplot(x=smooth.index, y=smooth.to_numpy(), ax=ax, errorbar=None, color=colour)
        ax.axhline(0.0, color="0.5", lw=0.8, ls=":")
        note = "boredom −100 included" if include_boredom else "familiar episodes left out"
        if symlog:
            symlog_axis(ax, _progress_linthresh(table))
            note += "; symlog axis"
        if ylim is not None:
            ax.set_ylim(*ylim)
            note += f"; y clipped to [{ylim[0]:g}, {ylim[1]:g}]"
        ax.set(xlabel="global step (frames)", ylabel="intrinsic reward (DA)",
               title=f"Figure 4E. Smoothed intrinsic reward — {condition} ({note})")
    return caption(fig, "Figure 4E (section 4.1.4)",
                   f"{condition}: the intrinsic reward (DA) averaged over runs and smoothed, against the global step")


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


def reward_estimates(run: pd.DataFrame, n_contexts: int, alpha: float | str) -> np.ndarray:
    """(n_episodes, n_contexts): each context's reward estimate R_c after each episode of one run.

    ``run`` is one run's episodes in episode order, from its first. R_c starts at 0 (as the
    PFC's reward model) and every episode but the first applies eq 14 to the estimate of
    its context, ``R_c <- reward_update(R_c, DA, eq14_rate(alpha, n_c))``
    (:mod:`neurocur.regions.pfc`; ``alpha`` a rate in (0, 1] or ``"sample_average"``, n_c
    the context's samples so far); what R_c is in terms of the PFC's model is said in
    :func:`fig_reward_function`.
    """
    require_columns(run, ["context", "da"], needed_by="reward_estimates")
    try:
        PFCParams(alpha=alpha)  # the PFC's own check of eq 14's rate
    except ConfigError:
        raise ValueError(f"alpha must be in (0, 1] or {SAMPLE_AVERAGE!r} (eq 14's learning rate), got {alpha!r}") from None
    da = run["da"].to_numpy(dtype=float)
    contexts = run["context"].to_numpy()
    estimate = np.zeros(n_contexts)
    samples = np.zeros(n_contexts, dtype=np.int64)
    estimates = np.empty((len(run), n_contexts))
    for t, (c, reward) in enumerate(zip(contexts, da)):
        if t > 0:  # the PFC has no previous context at the first episode and leaves its model as it is
            samples[c] += 1
            estimate[c] = reward_update(estimate[c], reward, eq14_rate(alpha, samples[c]))
        estimates[t] = estimate
    return estimates


def fig_reward_function(
    results: Results,
    run: int | None = None,
    condition: str | None = None,
    *,
    alpha: float | str | None = None,
    symlog: bool = True,
) -> Figure:
    """Figure 4G: the reward function per context over time, for one run.

    The PFC's reward model is ``R[o, a, o']`` per (previous context, action, context); after
    each episode but the run's first it applies eq 14, ``R <- (1 - alpha) R + alpha * DA``
    (:func:`neurocur.regions.pfc.reward_update`), to the entry of the episode's previous
    context ``o``, previous action ``a`` and context ``o'``, with the episode's DA. The
    plotted R_c (:func:`reward_estimates`) applies the same updates, with the same DA, in
    the same order, to one value per context ``c = o'``: it is the reward model the PFC
    would have if it pooled its entries ``R[., ., c]`` over the previous context and action,
    starting from 0. ``alpha`` is eq 14's learning rate; by default the condition's own: the ``alpha`` of its
    circuit's :class:`~neurocur.regions.pfc.PFCLSPI` region in the results folder's config.toml
    (:meth:`~neurocur.analysis.results.Results.region_param`), else ``PFCParams().alpha``. One line
    per context of the world, a step after each episode. With ``symlog`` the y-axis is
    linear only near zero (as in :func:`fig_neuromodulators`), so the rise of the
    learning-progress reward shows beside the boredom-driven drop.
    """
    require_columns(results.episodes, ["condition", "run", "episode", "step", "n_frames", "context", "da", "familiar"],
                    needed_by="fig_reward_function")
    condition, run, table = _one_run(results.episodes, condition, run)
    if alpha is None:
        alpha = results.region_param(PFCLSPI, "alpha").get(condition, PFCParams().alpha)
    alpha = alpha if isinstance(alpha, str) else float(alpha)  # a rate, or "sample_average"
    spec = results.spec_of(condition)
    n_contexts = len(spec.context_names)
    if table["context"].max() >= n_contexts:
        raise ValueError(f"episodes visit context {table['context'].max()} but the world has {n_contexts}")
    estimates = reward_estimates(table, n_contexts, alpha)
    steps = table["step"].to_numpy() + table["n_frames"].to_numpy()
    with style():
        fig, axes = figure()
        ax = axes[0, 0]
        colours = source_colours(spec.context_sources)
        for c, (name, source) in enumerate(zip(spec.context_names, spec.context_sources)):
            shown = spec.context_sources[:c].count(source)      # a second context of a source: dashed
            ax.plot(steps, estimates[:, c], drawstyle="steps-post", color=colours[source],
                    ls=("-", "--", ":", "-.")[shown % 4], label=f"{name} ({source})")
        ax.set(xlabel="global step (frames)", ylabel="estimated reward R(context)",
               title=f"Figure 4G. Reward function — {condition}, run {run} "
                     f"(eq 14, {'sample average' if alpha == SAMPLE_AVERAGE else f'α={alpha:g}'})")
        if symlog:
            symlog_axis(ax, _progress_linthresh(table))
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return caption(fig, "Figure 4G (section 4.1.4)",
                   f"{condition}, run {run}: the reward estimated for each context (eq 14) over the run, "
                   "coloured by the context's source")


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
    shares to mark (``{source or "none": {position: share of runs}}``) and ``note`` says what they are."""
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


def fig_neuromodulators(
    episodes: pd.DataFrame,
    run: int | None = None,
    condition: str | None = None,
    *,
    da_linthresh: float | None = None,
    captions: Mapping[str, str] | None = None,
) -> Figure:
    """DA, NE tonic, NE phasic and ε per episode for one run, module storage marked.

    Stacked panels sharing the step axis; each has the episodes as light dots, one line (their
    running median over :data:`TRACE_WINDOW` episodes: the NE signals jump between levels from
    one episode to the next, and a line through every episode is a dense hatching), in the
    condition's colour, plus a dashed vertical line (gid ``"module_learned"``) at every module
    storage. The ε panel is drawn only when the
    table has an ``epsilon`` column (the epsilon-greedy LC records it; other LC models need
    not), so there are three or four panels. DA is drawn on a symlog axis (linear within
    ``±da_linthresh``, default the 90th percentile of |DA| on unfamiliar episodes) so the
    −100 boredom rewards and the small learning-progress rewards both show (:func:`~neurocur.analysis.figures.layout.symlog_axis`).
    ``captions``: what each column is, by column (the run's region models' probe docs,
    :meth:`~neurocur.analysis.results.Results.probe_docs`), written above its panel; the NE
    panels' axes span [0, 1] when their values do.
    """
    require_columns(episodes, ["condition", "run", "episode", "step", "n_frames", "module_learned", "da", "familiar",
                               "ne_tonic", "ne_phasic"], needed_by="fig_neuromodulators")
    condition, run, table = _one_run(episodes, condition, run)
    steps = table["step"].to_numpy()
    events = (table["step"] + table["n_frames"])[table["module_learned"].astype(bool)].to_numpy()
    if da_linthresh is None:
        da_linthresh = _progress_linthresh(table)
    panels = [("da", "DA (intrinsic reward)"), ("ne_tonic", "NE tonic"), ("ne_phasic", "NE phasic")]
    if "epsilon" in table:
        panels.append(("epsilon", "ε"))
    colour = condition_colours(sorted(episodes["condition"].unique()))[condition]
    with style():
        fig, axes = figure(len(panels), 1, figsize=(8.0, 1.75 * len(panels)), sharex=True)
        for ax, (column, label) in zip(axes[:, 0], panels):
            values = table[column].to_numpy(dtype=float)
            ax.scatter(steps, values, s=2, color=colour, alpha=0.25, lw=0, rasterized=True)
            ax.plot(steps, pd.Series(values).rolling(TRACE_WINDOW, center=True, min_periods=1).median().to_numpy(),
                    color=colour, lw=1.2)
            for x in events:
                ax.axvline(x, color="0.3", ls="--", lw=0.8, gid=EVENT_GID)
            ax.set_ylabel(label)
            if column != "da" and np.nanmin(values, initial=0.0) >= 0.0 and np.nanmax(values, initial=0.0) <= 1.0:
                ax.set_ylim(-0.05, 1.05)
            if captions and column in captions:
                ax.set_title(f"{label}: {captions[column]}", loc="left", fontsize="small")
        symlog_axis(axes[0, 0], da_linthresh)
        fig.suptitle(f"Neuromodulators — {condition}, run {run}\n(dots: episodes; line: running median over "
                     f"{TRACE_WINDOW} episodes; dashed: module stored)", fontsize="medium")
        axes[-1, 0].set_xlabel("global step (frames)")
        axes[-1, 0].xaxis.set_major_formatter(KILO_FRAMES)
    return caption(fig, "none: the model's neuromodulators (the paper has no figure of them)",
                   f"{condition}, run {run}: DA, NE tonic, NE phasic (and ε) per episode with their running median, "
                   "module storage marked")
