"""Seaborn figures of one run's reward and neuromodulator signals (paper Figures 4E, 4G).

The intrinsic reward (DA) against the global step (Figure 4E), the PFC's reward estimate of
each context over a run (Figure 4G, eq 14) and the neuromodulator traces of a run (DA, NE
tonic and phasic, ε). Every function returns a :class:`matplotlib.figure.Figure` in the style
of :mod:`neurocur.analysis.figures.style` and checks on entry that its table has the columns it
reads (:func:`neurocur.contract.require_columns`), so a table without, say, an LC's columns gives
an error naming them and the role producing them; a column that only some region models record
(``epsilon``) is drawn when present. DA is drawn on a symlog axis, linear only
near zero, so the −100 boredom rewards and the small learning-progress rewards both show. The
learning curves (Figures 4D, 4F, the storage order) are in
:mod:`~neurocur.analysis.figures.learning`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.figure import Figure

from neurocur.analysis.results import Results
from neurocur.config import ConfigError
from neurocur.contract import require_columns
from neurocur.regions.pfc import PFCLSPI, SAMPLE_AVERAGE, PFCParams, eq14_rate, reward_update

from .layout import symlog_axis
from .learning import EVENT_GID, KILO_FRAMES, condition_of, one_run
from .style import caption, condition_colours, figure, source_colours, style

__all__ = [
    "fig_intrinsic_reward",
    "fig_reward_function",
    "fig_neuromodulators",
    "reward_estimates",
]

#: Episodes in the running median drawn over a per-episode trace (:func:`fig_neuromodulators`).
TRACE_WINDOW = 25


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

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table (columns ``condition``, ``run``, ``step``, ``da``, ``familiar``).
    condition : str or None
        The condition drawn; None for the first in name order.
    bin_steps : int
        Frames per bin, > 0.
    window : int
        Bins in the centred moving average, >= 1 (1: no smoothing).
    include_boredom : bool
        Keep the familiar episodes (their −100 boredom reward); False leaves them out.
    symlog : bool
        A symlog y-axis (``neurocur.analysis.figures.layout.symlog_axis``), linear within the 90th
        percentile of |DA| on unfamiliar episodes; False keeps it linear.
    ylim : (float, float) or None
        The y-axis limits, said in the title; None leaves matplotlib's.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: the smoothed mean DA against the global step.

    Raises
    ------
    ValueError
        When ``window`` or ``bin_steps`` is below its range.
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


def reward_estimates(run: pd.DataFrame, n_contexts: int, alpha: float | str) -> np.ndarray:
    """(n_episodes, n_contexts): each context's reward estimate R_c after each episode of one run.

    ``run`` is one run's episodes in episode order, from its first. R_c starts at 0 (as the
    PFC's reward model) and every episode but the first applies eq 14 to the estimate of
    its context, ``R_c <- reward_update(R_c, DA, eq14_rate(alpha, n_c))``
    (:mod:`neurocur.regions.pfc`; ``alpha`` a rate in (0, 1] or ``"sample_average"``, n_c
    the context's samples so far); what R_c is in terms of the PFC's model is said in
    :func:`fig_reward_function`.

    Parameters
    ----------
    run : pandas.DataFrame
        One run's episodes in episode order (columns ``context``, the context index, and ``da``).
    n_contexts : int
        The world's contexts (every ``context`` is below it).
    alpha : float or str
        Eq 14's learning rate, in (0, 1], or ``"sample_average"`` (rate 1 / n_c).

    Returns
    -------
    numpy.ndarray
        Shape (episodes, ``n_contexts``): row t holds each context's estimate after episode t.

    Raises
    ------
    ValueError
        When ``alpha`` is neither a rate in (0, 1] nor ``"sample_average"``.
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

    Parameters
    ----------
    results : Results
        A results folder's tables and config (``neurocur.analysis.results.Results``).
    run : int or None
        The run drawn; None for the condition's lowest-numbered run.
    condition : str or None
        The condition drawn; None for the first in name order.
    alpha : float, str or None
        Eq 14's learning rate (in (0, 1], or ``"sample_average"``); None for the condition's own (see above).
    symlog : bool
        A symlog y-axis, linear within the 90th percentile of |DA| on the run's unfamiliar episodes; False
        keeps it linear.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: a step line per context, in its source's colour.

    Raises
    ------
    ValueError
        When the run visits a context index the condition's world does not have, or ``alpha`` is out of range.
    """
    require_columns(results.episodes, ["condition", "run", "episode", "step", "n_frames", "context", "da", "familiar"],
                    needed_by="fig_reward_function")
    condition, run, table = one_run(results.episodes, condition, run)
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

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table (columns ``condition``, ``run``, ``episode``, ``step``, ``n_frames``,
        ``module_learned``, ``da``, ``familiar``, ``ne_tonic``, ``ne_phasic``; ``epsilon`` when recorded).
    run : int or None
        The run drawn; None for the condition's lowest-numbered run.
    condition : str or None
        The condition drawn; None for the first in name order.
    da_linthresh : float or None
        Half-width of the DA axis's linear range; None for the 90th percentile of |DA| on the run's
        unfamiliar episodes (1 when there is none).
    captions : mapping of str to str or None
        Text written above a panel, by column; None writes none.

    Returns
    -------
    matplotlib.figure.Figure
        Three or four stacked panels sharing the step axis.
    """
    require_columns(episodes, ["condition", "run", "episode", "step", "n_frames", "module_learned", "da", "familiar",
                               "ne_tonic", "ne_phasic"], needed_by="fig_neuromodulators")
    condition, run, table = one_run(episodes, condition, run)
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
