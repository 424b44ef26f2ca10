"""Seaborn figures of the neuromodulator and behaviour analyses.

Each function draws the tidy output of one analysis module and returns a
:class:`matplotlib.figure.Figure` in the style of :mod:`neurocur.analysis.figures.style`:

* :func:`fig_inverted_u` — performance against a level, runs as points, level means with
  Student's t intervals, and the two lines of Simonsohn's (2018) test
  (:mod:`~neurocur.analysis.stats.inverted_u`);
* :func:`fig_occupancy` — the share of frames in chosen contexts over time (the noisy TV;
  :func:`~neurocur.analysis.stats.dwell.occupancy`), and :func:`fig_over_time` for any binned signal
  (DA in the noise context, :func:`~neurocur.analysis.stats.dwell.signal_over_time`);
* :func:`fig_event_locked` — event-locked DA and NE with intervals across runs
  (:func:`~neurocur.analysis.stats.event_locked.event_locked_average`);
* :func:`fig_tonic_phasic` — phasic against tonic NE per run and context
  (:func:`~neurocur.analysis.stats.event_locked.tonic_phasic`);
* :func:`fig_efficiency` — frames until every learnable source is learned and frames in the
  unlearnable contexts, two conditions paired by run (:mod:`~neurocur.analysis.stats.efficiency`).

Engagement against learnability (the Goldilocks curve) is
:func:`~neurocur.analysis.figures.goldilocks.fig_goldilocks`.

Intervals of means over runs are 95 % percentile bootstrap intervals (Efron & Tibshirani
1993; seaborn's, seeded with :data:`~neurocur.analysis.stats.bootstrap.BOOTSTRAP_SEED`) unless a
function says otherwise.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.figure import Figure

from neurocur.analysis.stats.bootstrap import BOOTSTRAP_SEED, N_BOOT
from neurocur.analysis.stats.dwell import context_indices, spec_of
from neurocur.analysis.stats.inverted_u import level_means, two_lines
from neurocur.analysis.stats.report import family_note
from neurocur.analysis.stats.significance import TESTS
from neurocur.contract import require_columns

from .style import caption, condition_colours, figure, style

__all__ = ["fig_inverted_u", "fig_occupancy", "fig_over_time", "fig_event_locked", "fig_tonic_phasic",
           "fig_efficiency"]

_CI = {"errorbar": ("ci", 95), "n_boot": N_BOOT, "seed": BOOTSTRAP_SEED}


def _groups(table: pd.DataFrame, by: str | None) -> list[tuple[str, pd.DataFrame]]:
    if by is None:
        return [("", table)]
    require_columns(table, [by], needed_by="figure")
    return [(str(name), part) for name, part in table.groupby(by, sort=True)]


def fig_inverted_u(
    table: pd.DataFrame,
    x: str,
    y: str,
    run: str | None = "run",
    *,
    by: str | None = None,
    alpha: float = 0.05,
    paired: bool = True,
) -> Figure:
    """Performance ``y`` against a level ``x``: one panel per group of ``by`` (e.g. per model).

    Each panel: the runs as grey points (jittered by 2 % of the level range), the level means
    with Student's t 95 % intervals (:func:`~neurocur.analysis.stats.inverted_u.level_means`), the
    two lines of :func:`~neurocur.analysis.stats.inverted_u.two_lines` (each drawn with its slope
    through the mean of its side) and the break (dotted); the title gives both slopes, their
    one-sided p-values and the verdict.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per observation (e.g. per run and level), with the columns ``x`` and ``y`` (and ``run``
        and ``by`` when given).
    x : str
        The level column.
    y : str
        The performance column.
    run : str or None
        The column naming each row's run (the test's run intercepts); None for none.
    by : str or None
        A panel per value of this column; None for one panel.
    alpha : float
        The level of each one-sided slope test, in (0, 1).
    paired : bool
        Give each run observed at two or more levels its own intercept in the test.

    Returns
    -------
    matplotlib.figure.Figure
        A row of panels sharing the y-axis.
    """
    require_columns(table, [x, y], needed_by="fig_inverted_u")
    groups = _groups(table, by)
    with style():
        fig, axes = figure(1, len(groups), figsize=(4.6 * len(groups), 3.8), sharey=True)
        rng = np.random.default_rng(BOOTSTRAP_SEED)
        for ax, (name, part) in zip(axes[0], groups):
            xv, yv = part[x].to_numpy(dtype=float), part[y].to_numpy(dtype=float)
            spread = np.ptp(xv[np.isfinite(xv)]) if np.isfinite(xv).any() else 1.0
            ax.scatter(xv + rng.uniform(-0.02, 0.02, len(xv)) * spread, yv, s=10, color="0.6", alpha=0.7,
                       label="runs")
            means = level_means(part, x, y)
            ax.errorbar(means[x], means["mean"], fmt="o-", color="C0", capsize=3, label="mean (95 % t CI)",
                        yerr=[means["mean"] - means["ci_low"], means["ci_high"] - means["mean"]])
            result = two_lines(part, x, y, run, alpha=alpha, paired=paired)
            xc = result["break_point"]
            for side, slope, colour in ((xv <= xc, result["slope1"], "C1"), (xv >= xc, result["slope2"], "C3")):
                keep = side & np.isfinite(yv)
                if np.isfinite(slope) and keep.any():
                    ends = np.array([xv[keep].min(), xv[keep].max()])
                    ax.plot(ends, yv[keep].mean() + slope * (ends - xv[keep].mean()), color=colour, lw=2)
            ax.axvline(xc, color="0.3", ls=":", lw=1)
            verdict = "interior peak" if result["interior_peak"] else "no interior peak"
            ax.set(xlabel=x, ylabel=y, title=(f"{name + ': ' if name else ''}{verdict}\n"
                                              f"b1={result['slope1']:.3g} (p={result['p1']:.2g}), "
                                              f"b2={result['slope2']:.3g} (p={result['p2']:.2g})"))
        axes[0, 0].legend(loc="best", fontsize="small")
    return fig


def fig_occupancy(table: pd.DataFrame, contexts, spec=None, *, hue: str = "condition") -> Figure:
    """The share of frames spent in ``contexts`` (indices or names; names need ``spec``) per time bin.

    ``table``: :func:`~neurocur.analysis.stats.dwell.occupancy`. The shares of the chosen contexts
    are summed per run and bin; one line per ``hue`` (the mean over runs, 95 % bootstrap
    interval).

    Parameters
    ----------
    table : pandas.DataFrame
        ``neurocur.analysis.stats.dwell.occupancy`` of the episodes.
    contexts : int, str or sequence of int or str
        The contexts whose shares are summed: indices, or names (which need ``spec``).
    spec : SourceSpec, mapping of str to SourceSpec, or None
        The world's sources, or each condition's by condition, to name contexts; None for indices only.
    hue : str
        A line per value of this column.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: the share of frames against the global step.

    Raises
    ------
    ValueError
        When a context is neither an index nor a name of the condition's world.
    """
    require_columns(table, ["condition", "run", "bin", "step", "context", "share", hue], needed_by="fig_occupancy")
    keep = np.zeros(len(table), dtype=bool)
    for condition in table["condition"].unique():
        chosen = context_indices(contexts, spec_of(spec, condition), needed_by="fig_occupancy")
        keep |= ((table["condition"] == condition) & table["context"].isin(chosen)).to_numpy()
    grouping = list(dict.fromkeys(["condition", hue, "run", "bin", "step"]))
    summed = table[keep].groupby(grouping, as_index=False)["share"].sum()
    names = contexts if isinstance(contexts, (str, int)) else ", ".join(map(str, contexts))
    fig = fig_over_time(summed, "share", hue=hue, ylabel=f"share of frames in {names}",
                        title=f"Occupancy of {names} over time ({summed['run'].nunique()} runs)")
    fig.axes[0].set_ylim(-0.02, 1.02)
    return fig


def fig_over_time(table: pd.DataFrame, column: str, *, hue: str = "condition", ylabel: str | None = None,
                  title: str | None = None) -> Figure:
    """A binned per-run quantity against time, e.g. :func:`~neurocur.analysis.stats.dwell.signal_over_time`
    (DA in a noise context): one line per ``hue``, the mean over runs with its 95 % bootstrap interval.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per run and bin (columns ``run``, ``step``, ``column`` and ``hue``).
    column : str
        The quantity drawn.
    hue : str
        A line per value of this column.
    ylabel : str or None
        The y label; None for ``column``.
    title : str or None
        The title; None for the column and the number of runs.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: the quantity against the global step.
    """
    require_columns(table, ["run", "step", column, hue], needed_by="fig_over_time")
    with style():
        fig, axes = figure()
        ax = axes[0, 0]
        sns.lineplot(data=table, x="step", y=column, hue=hue, ax=ax, **_CI)
        ax.set(xlabel="global step (frames; bin start)", ylabel=ylabel or column,
               title=title or f"{column} over time ({table['run'].nunique()} runs)")
    return fig


def fig_event_locked(table: pd.DataFrame, *, hue: str = "condition") -> Figure:
    """Event-locked averages: one panel per (signal, event), one line per ``hue`` with its band.

    ``table``: :func:`~neurocur.analysis.stats.event_locked.event_locked_average` (its ``ci_low`` and
    ``ci_high`` are the bands; pass ``by_context=True`` output with ``hue="context"`` for one
    condition at a time).

    Parameters
    ----------
    table : pandas.DataFrame
        ``neurocur.analysis.stats.event_locked.event_locked_average`` of the episodes (columns ``event``,
        ``signal``, ``lag``, ``mean``, ``ci_low``, ``ci_high`` and ``hue``).
    hue : str
        A line per value of this column.

    Returns
    -------
    matplotlib.figure.Figure
        A row of panels per signal, a column per event.
    """
    require_columns(table, ["event", "signal", "lag", "mean", "ci_low", "ci_high", hue], needed_by="fig_event_locked")
    signals, kinds = list(dict.fromkeys(table["signal"])), list(dict.fromkeys(table["event"]))
    levels = list(dict.fromkeys(table[hue]))
    palette = dict(zip(levels, sns.color_palette("colorblind", len(levels))))
    with style():
        fig, axes = figure(len(signals), len(kinds), figsize=(3.6 * len(kinds) + 1.6, 2.4 * len(signals)),
                           sharex=True)
        for i, signal in enumerate(signals):
            for j, kind in enumerate(kinds):
                ax = axes[i, j]
                for level in levels:
                    part = table[(table["signal"] == signal) & (table["event"] == kind) & (table[hue] == level)]
                    part = part.sort_values("lag")
                    ax.plot(part["lag"], part["mean"], color=palette[level], label=str(level))
                    ax.fill_between(part["lag"], part["ci_low"], part["ci_high"], color=palette[level], alpha=0.2,
                                    lw=0)
                ax.axvline(0, color="0.5", ls=":", lw=0.8)
                if i == 0:
                    ax.set_title(kind.replace("_", " "))
                if j == 0:
                    ax.set_ylabel(signal)
                if i == len(signals) - 1:
                    ax.set_xlabel("episodes from the event")
        axes[0, -1].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small", title=hue)
    return fig


def fig_tonic_phasic(table: pd.DataFrame, tonic: str = "ne_tonic", phasic: str = "ne_phasic", *,
                     hue: str = "condition") -> Figure:
    """Phasic against tonic NE, one point per run and context (:func:`~neurocur.analysis.stats.event_locked.tonic_phasic`).

    Parameters
    ----------
    table : pandas.DataFrame
        ``neurocur.analysis.stats.event_locked.tonic_phasic`` of the episodes.
    tonic : str
        The tonic NE column (x).
    phasic : str
        The phasic NE column (y).
    hue : str
        A colour per value of this column.

    Returns
    -------
    matplotlib.figure.Figure
        One scatter plot.
    """
    require_columns(table, [tonic, phasic, hue], needed_by="fig_tonic_phasic")
    with style():
        fig, axes = figure(figsize=(5.0, 4.0))
        sns.scatterplot(data=table, x=tonic, y=phasic, hue=hue, ax=axes[0, 0], s=22, alpha=0.8)
        axes[0, 0].set(xlabel="tonic NE (mean per run and context)", ylabel="phasic NE (mean per run and context)")
    return fig


def fig_efficiency(table: pd.DataFrame, tests: pd.DataFrame, a: str, b: str) -> Figure:
    """How efficiently ``a`` and ``b`` learn, paired by run: ``table`` is their
    :func:`~neurocur.analysis.stats.efficiency.efficiency_per_run`, ``tests`` the efficiency family
    of the order table (``paired_tests(results, a)["efficiency"]``,
    :func:`~neurocur.analysis.stats.report.paired_tests`).

    Left: frames until every learnable source is learned; a run that did not is drawn hollow
    at the table's cut-off (its ``horizon``, the dashed line), where it is censored. Right: frames in the unlearnable
    contexts. A grey line joins the two runs of a seed. Each title gives the paired test of ``b``
    against the reference ``a`` read from ``tests`` (every condition against ``a``, adjusted
    together), so the figure and the table show the same adjusted p-value; the title names the
    adjustment and the family's size.

    Parameters
    ----------
    table : pandas.DataFrame
        The efficiency per run (columns ``condition``, ``run``, ``learned_all``,
        ``frames_to_learn_all_censored``, ``frames_unlearnable``, ``horizon``).
    tests : pandas.DataFrame
        The efficiency family of the paired tests (columns ``metric``, ``method``, ``b``, ``p_adjusted``,
        ``adjustment``, ``n_tests``, ``n_pairs``).
    a : str
        The reference condition, drawn left.
    b : str
        The condition tested against it, drawn right.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, each run of a seed joined to its pair.
    """
    require_columns(table, ["condition", "run", "learned_all", "frames_to_learn_all_censored", "frames_unlearnable",
                            "horizon"], needed_by="fig_efficiency")
    require_columns(tests, ["metric", "method", "b", "p_adjusted", "adjustment", "n_tests", "n_pairs"],
                    needed_by="fig_efficiency (tests)")
    tests = tests[tests["b"] == b].set_index("metric")
    pairs = table[table["condition"].isin([a, b])].pivot(index="run", columns="condition")
    pairs = pairs.dropna(subset=[("frames_to_learn_all_censored", a), ("frames_to_learn_all_censored", b)])
    horizon = table["horizon"].iloc[0]
    colours = condition_colours(sorted(table["condition"].unique()))
    with style():
        fig, axes = figure(1, 2, figsize=(9.0, 4.2))
        for ax, metric, label in ((axes[0, 0], "frames_to_learn_all_censored", "frames to learn all learnable sources"),
                                  (axes[0, 1], "frames_unlearnable", "frames in unlearnable contexts")):
            for _, row in pairs.iterrows():
                ax.plot([0, 1], [row[(metric, a)], row[(metric, b)]], color="0.7", lw=0.8, zorder=1)
            for k, condition in enumerate((a, b)):
                values = pairs[(metric, condition)].to_numpy(dtype=float)
                done = pairs[("learned_all", condition)].astype(bool).to_numpy() if metric != "frames_unlearnable" \
                    else np.ones(len(values), dtype=bool)
                colour = colours[condition]
                ax.scatter(np.full(done.sum(), k), values[done], color=colour, zorder=2, s=24)
                ax.scatter(np.full((~done).sum(), k), values[~done], facecolors="none", edgecolors=colour, zorder=2,
                           s=24)
            if metric != "frames_unlearnable":
                ax.axhline(horizon, color="0.4", ls="--", lw=0.8)
            if metric in tests.index:
                test = tests.loc[metric]
                note = f"{TESTS[test['method']][0]} p = {test['p_adjusted']:.2g}\n" \
                       f"({family_note(tests)}; n = {int(test['n_pairs'])} pairs)"
            else:
                note = f"not tested ({b}'s runs repeat another condition's)"
            ax.set(xticks=[0, 1], xticklabels=[a, b], xlim=(-0.4, 1.4), ylabel=label, title=f"{label}\n{note}")
    return caption(fig, "none: section 4.3's claim (random exploration learns nothing), tested",
                   f"{a} against {b} paired by run: frames to learn every learnable source and frames in the "
                   "unlearnable contexts, with the order table's adjusted p-values")
