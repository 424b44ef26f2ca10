"""Figures of the simulated iCub experiment (paper section 4.2, Figures 6–7).

The tables are those of :mod:`neurocur.analysis.stats.icub`. Figures (each a
:class:`matplotlib.figure.Figure` in the style of :mod:`neurocur.analysis.figures.style`):

- :func:`fig_module_error` — Figures 6B (``module=0``) and 6C (``module=1``): the
  adaptive module's estimation error while the k-th module learns;
- :func:`fig_order` — Figure 6D: which object was learned first and second;
- :func:`fig_frames` — a strip of frames from both contexts (Figure 6A);
- :func:`fig_feature_output` — the slowest output over reference episodes against the
  object's displacement (Figure 7).

:class:`ICubFigures` is the figure set of a results folder of the ``icub`` world type
(:func:`neurocur.analysis.figures.sets.write_all`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.figure import Figure

from neurocur.analysis.paper import ICUB_CURIOUS
from neurocur.analysis.results import Results
from neurocur.analysis.stats.icub import ICUB, learning_segments, load_features
from neurocur.analysis.stats.order import require_order_columns
from neurocur.analysis.stats.verdict import paper_range
from neurocur.contexts import build_world
from neurocur.contract import require_columns
from neurocur.regions.hpc import HPCROC

from .learning import condition_of, fig_order_counts
from .reward import fig_neuromodulators, fig_reward_function
from .sets import FIGURE_SETS, FigureSet
from .style import caption, condition_colours, figure, style

__all__ = ["fig_module_error", "fig_order", "fig_frames", "fig_feature_output", "ICubFigures"]


def fig_module_error(
    episodes: pd.DataFrame,
    module: int = 0,
    *,
    bin_frames: int = 2000,
    threshold: float | None = None,
    min_runs: int = 3,
) -> Figure:
    """Figures 6B (``module=0``) and 6C (``module=1``): the error while module ``module+1`` learns.

    The adaptive module's context error (column ``error``: the mean of the context's stored
    eq-10 errors, eq 11 / M) on its unfamiliar episodes, against the frames since it started
    learning (:func:`learning_segments`), averaged per run over bins of ``bin_frames``, then
    over runs (mean ± sd band), one line per condition; bins that fewer than ``min_runs``
    runs reach are left out (a module learns for a different time in each run).
    ``threshold`` draws the freeze threshold (dashed). Runs that never reached this module
    do not count.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of an iCub results folder (columns ``condition``, ``run``, ``step``,
        ``n_modules``, ``module_learned``, ``error``).
    module : int
        The learning module, 0-based (0: Figure 6B, 1: Figure 6C), >= 0.
    bin_frames : int
        Frames per bin, > 0.
    threshold : float or None
        The freeze threshold, drawn dashed; None draws none.
    min_runs : int
        Bins reached by fewer runs are left out (at most the runs that reached the module are asked for).

    Returns
    -------
    matplotlib.figure.Figure
        One axes: a line per condition.
    """
    if module < 0:
        raise ValueError(f"module must be >= 0, got {module}")
    if bin_frames <= 0:
        raise ValueError(f"bin_frames must be a positive number of frames, got {bin_frames}")
    require_columns(episodes, ["condition", "run", "step", "n_modules", "module_learned", "error"],
                    needed_by="fig_module_error")
    table = learning_segments(episodes)
    table = table[(table["learning_module"] == module) & table["error"].notna()]
    table = table.assign(frames_in=table["frames_in"] // bin_frames * bin_frames + bin_frames / 2)
    binned = table.groupby(["condition", "run", "frames_in"], as_index=False)["error"].mean()
    reached = binned.groupby(["condition", "frames_in"])["run"].transform("nunique")
    binned = binned[reached >= min(min_runs, binned["run"].nunique())]
    conditions = sorted(episodes["condition"].unique())
    label = "6B" if module == 0 else "6C" if module == 1 else ""
    with style():
        fig, axes = figure()
        ax = axes[0, 0]
        if binned.empty:
            ax.text(0.5, 0.5, f"no run reached module {module + 1}", ha="center", va="center", transform=ax.transAxes)
        else:
            runs = binned.groupby("condition")["run"].nunique()
            binned["condition"] = binned["condition"].map(lambda c: f"{c} ({runs.get(c, 0)} runs)")
            order = [f"{c} ({runs.get(c, 0)} runs)" for c in conditions if c in runs]
            colours = condition_colours(conditions)
            sns.lineplot(data=binned, x="frames_in", y="error", hue="condition", hue_order=order,
                         errorbar="sd", ax=ax, palette=[colours[c] for c in conditions if c in runs])
        if threshold is not None:
            ax.axhline(threshold, color="0.3", ls="--", lw=0.9, label=f"freeze threshold {threshold:g}")
            ax.legend(loc="upper right")
        total = episodes.groupby("condition")["run"].nunique()
        reached = ", ".join(f"{c} {runs.get(c, 0) if not binned.empty else 0}/{total[c]}" for c in conditions)
        paper_runs = f"; the paper: both learned {ICUB_CURIOUS['both learned'].cell()}" if module <= 1 else ""
        ax.set(xlabel=f"frames since module {module + 1} started learning",
               ylabel="estimation error (mean over states)",
               title=(f"Figure {label}: estimation error while module {module + 1} learns (mean ± sd)\n"
                      f"runs that reached it: {reached}{paper_runs}").replace("Figure : ", ""))
    return caption(fig, f"Figure {label} (section 4.2.2)" if label else "none",
                   f"the adaptive module's estimation error while module {module + 1} learns, mean ± sd over the "
                   "runs that reached it, per condition")


def fig_order(modules: pd.DataFrame, episodes: pd.DataFrame) -> Figure:
    """Figure 6D: which object was stored first and second, counted over runs, per condition.

    The paper (:data:`neurocur.analysis.paper.ICUB_CURIOUS`, section 4.2.2): the easier topple
    representation was learned first in 14 of 15 runs, and both objects in 15/15 (implied:
    Figure 6C averages the second module's learning over the runs), so no run is without a
    second module. Both are marked on each panel, scaled to its runs: a black diamond on the
    bar of topple first and on the bar of "none" second (at 0).

    Parameters
    ----------
    modules : pandas.DataFrame
        The modules table of an iCub results folder.
    episodes : pandas.DataFrame
        Its episodes table.

    Returns
    -------
    matplotlib.figure.Figure
        ``fig_order_counts`` of the iCub world, with the paper's marks.
    """
    require_order_columns(episodes, modules, needed_by="fig_order")
    first, both = (paper_range(ICUB_CURIOUS[key].value)[0] for key in ("topple first", "both learned"))
    fig = fig_order_counts(
        Results.of(episodes, modules, ICUB), marks={"topple": {1: first}, "none": {2: 1.0 - both}},
        note=(f"Figure 6D: storage order. ◆ the paper: topple first {ICUB_CURIOUS['topple first'].value}, "
              f"both learned {ICUB_CURIOUS['both learned'].cell()} (no run without a second module)"))
    return caption(fig, "Figure 6D (section 4.2.2)",
                   "which object each run stored first and second, per condition; diamonds: the paper's topple "
                   "first 14/15 and both learned 15/15, scaled to the runs")


def fig_frames(world, episode_index: int = 0, n_frames: int = 5) -> Figure:
    """A strip of frames of episode ``episode_index`` of each context (Figure 6A).

    Rows: contexts; columns: ``n_frames`` frames evenly spaced from the first to the last,
    each titled with its frame number, arm state and the object's displacement (cm).

    Parameters
    ----------
    world : ICubWorld
        A built iCub world (``neurocur.contexts.icub.ICubWorld``); its episodes are read from its cache.
    episode_index : int
        The episode of each context shown.
    n_frames : int
        Frames per context, >= 2.

    Returns
    -------
    matplotlib.figure.Figure
        A row of frames per context.
    """
    if n_frames < 2:
        raise ValueError(f"n_frames must be >= 2, got {n_frames}")
    with style():
        fig, axes = figure(world.n_contexts, n_frames, figsize=(2.2 * n_frames, 2.0 * world.n_contexts))
        for c, name in enumerate(world.context_names):
            ep = world.episode(c, episode_index)
            d = world.displacement(c, episode_index)
            for ax, t in zip(axes[c], np.linspace(0, len(d) - 1, n_frames).round().astype(int)):
                ax.imshow(ep.frames[t].reshape(world.frame_shape), cmap="gray", vmin=0.0, vmax=1.0)
                ax.set_title(f"{name} t={t} s={ep.states[t]}\nmoved {100 * d[t]:.1f} cm", fontsize=8)
                ax.set_axis_off()
        fig.suptitle(f"Episode {episode_index} of each context (contact at "
                     + ", ".join(f"t={world.contact_frame(c, episode_index)}" for c in range(world.n_contexts)) + ")")
    return fig


def _feature_run(features: pd.DataFrame, condition: str, run: int | None) -> int:
    table = features[features["condition"] == condition]
    if table.empty:
        raise ValueError(f"condition {condition!r} stored no module (no slow-feature outputs)")
    if run is not None:
        if run not in set(table["run"]):
            raise ValueError(f"run {run} of condition {condition!r} stored no module; have {sorted(set(table['run']))}")
        return int(run)
    n = table.groupby("run")["module"].nunique()
    return int(n.idxmax())  # the first run with the most modules


def fig_feature_output(
    features: pd.DataFrame,
    modules: pd.DataFrame,
    condition: str | None = None,
    run: int | None = None,
) -> Figure:
    """Figure 7: each stored module's slowest output y₀ against the object's displacement.

    One run (default: the condition's first run with the most modules); one row per stored
    module, one column per context. Each panel shows y₀ (left axis) and the object's
    displacement in cm (right axis, dashed) over the reference episodes, laid end to end
    (vertical lines separate episodes; dots mark the hand's first contact), and |corr|
    between the two over every cached episode of the module's own context (``quality``).

    Parameters
    ----------
    features : pandas.DataFrame
        The slow-feature outputs of a results folder (``neurocur.analysis.stats.icub.load_features``).
    modules : pandas.DataFrame
        Its modules table (columns ``condition``, ``run``, ``module``, ``source``, ``quality``,
        ``other_quality``).
    condition : str or None
        The condition drawn; None for the first in name order that has outputs.
    run : int or None
        The run drawn; None for the condition's first run with the most modules.

    Returns
    -------
    matplotlib.figure.Figure
        A panel per stored module and context.

    Raises
    ------
    ValueError
        When the condition, or the run asked for, stored no module.
    """
    require_columns(features, ["condition", "run", "module", "context", "episode_index", "frame", "contact_frame",
                               "displacement", "y0"], needed_by="fig_feature_output (features table)")
    require_columns(modules, ["condition", "run", "module", "source", "quality", "other_quality"],
                    needed_by="fig_feature_output (modules table)")
    condition = condition_of(features, condition)
    run = _feature_run(features, condition, run)
    table = features[(features["condition"] == condition) & (features["run"] == run)]
    mods = modules[(modules["condition"] == condition) & (modules["run"] == run)].set_index("module")
    ranks = sorted(table["module"].unique())
    contexts = sorted(table["context"].unique())
    palette = sns.color_palette("deep", 2)
    with style():
        fig, axes = figure(len(ranks), len(contexts), figsize=(5.0 * len(contexts), 2.6 * len(ranks)), sharex="col")
        for r, m in enumerate(ranks):
            for k, c in enumerate(contexts):
                ax = axes[r, k]
                part = table[(table["module"] == m) & (table["context"] == c)].sort_values(["episode_index", "frame"])
                x = np.arange(len(part))
                ax.plot(x, part["y0"].to_numpy(), color=palette[0], lw=1.0)
                twin = ax.twinx()
                twin.plot(x, 100 * part["displacement"].to_numpy(), color=palette[1], lw=1.0, ls="--")
                twin.grid(False)
                bounds = np.flatnonzero(np.diff(part["episode_index"].to_numpy())) + 0.5
                for b in bounds:
                    ax.axvline(b, color="0.6", lw=0.8)
                contact = x[(part["frame"] == part["contact_frame"]).to_numpy()]
                ax.plot(contact, part["y0"].to_numpy()[contact], "o", color="0.2", ms=3)
                name = ICUB.context_names[c]
                info = mods.loc[m] if m in mods.index else None
                learned = f"learned in {info['source']}" if info is not None else ""
                own = info is not None and info["source"] == name
                corr = info["quality"] if own else (info["other_quality"] if info is not None else math.nan)
                ax.set_title(f"module {m + 1} ({learned}) on {name}: |corr(y₀, displacement)| = {corr:.2f}",
                             fontsize=9)
                ax.set_ylabel("y₀", color=palette[0])
                twin.set_ylabel("displacement (cm)", color=palette[1])
                if r == len(ranks) - 1:
                    ax.set_xlabel("frame (reference episodes end to end)")
        fig.suptitle(f"Slowest feature vs the object's displacement — {condition}, run {run}")
    return fig


@FIGURE_SETS.register("icub")
class ICubFigures(FigureSet):
    """The iCub figures (Figures 6B–D, 6A, 7 and per condition the reward function and neuromodulators).

    Draws ``module_error_1`` (6B), ``module_error_2`` (6C), ``order_counts`` (6D), ``frames``
    (the world's episode 0 of each context; the world is rebuilt from ``config.toml``, reading
    the episode cache), per condition ``feature_output_<condition>`` (when it stored a module),
    ``reward_function_<condition>`` and ``neuromodulators_<condition>``. The freeze threshold
    drawn is the ``threshold`` of the conditions' :class:`~neurocur.regions.hpc.HPCROC` region
    when they share one.
    """

    def draw(self, results: Results) -> dict[str, Figure]:
        episodes, modules = results.episodes, results.modules
        features = load_features(results.path)
        thresholds = {float(t) for t in results.region_param(HPCROC, "threshold").values()}
        threshold = thresholds.pop() if len(thresholds) == 1 else None
        figures = {
            "module_error_1": fig_module_error(episodes, 0, threshold=threshold),
            "module_error_2": fig_module_error(episodes, 1, threshold=threshold),
            "order_counts": fig_order(modules, episodes),
            "frames": fig_frames(build_world(next(iter(results.config["conditions"].values()))["world"])),
        }
        for condition in results.conditions:
            if (features["condition"] == condition).any():
                figures[f"feature_output_{condition}"] = fig_feature_output(features, modules, condition)
            figures[f"reward_function_{condition}"] = fig_reward_function(results, condition=condition)
            figures[f"neuromodulators_{condition}"] = fig_neuromodulators(episodes, condition=condition)
        return figures
