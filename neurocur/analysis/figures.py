"""Seaborn figures of a results folder (paper Figures 4D–G and more).

Every function returns a :class:`matplotlib.figure.Figure` drawn on an Agg canvas
(no pyplot state, no window, nothing to close); :func:`write_all` saves them as PNG.

Reward function (Figure 4G): the PFC's running reward estimate per context is
recomputed from the episodes' intrinsic rewards with eq 14,
``R_c <- (1 - alpha) R_c + alpha * DA`` at every visit of context ``c`` (R_c = 0 before
the first reward); ``alpha=None`` gives the sample average instead. The reward of an
episode is attributed to the context in which it was earned.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from neurocur.analysis.io import load
from neurocur.analysis.stats import SYNTHETIC, SourceSpec, learning_times, position_counts

__all__ = [
    "fig_cumulative_error",
    "fig_intrinsic_reward",
    "fig_learning_time",
    "fig_reward_function",
    "fig_order_counts",
    "fig_neuromodulators",
    "write_all",
]

#: gid of the vertical lines marking module storage, so they can be told from data lines.
EVENT_GID = "module_learned"


@contextmanager
def _style() -> Iterator[None]:
    with sns.axes_style("whitegrid"), sns.plotting_context("notebook", font_scale=0.9):
        yield


def _figure(nrows: int = 1, ncols: int = 1, *, figsize=(7.0, 4.0), **kwargs) -> tuple[Figure, np.ndarray]:
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes


def _condition(episodes: pd.DataFrame, condition: str | None) -> str:
    conditions = sorted(episodes["condition"].unique())
    if not conditions:
        raise ValueError("the episodes table is empty")
    if condition is None:
        return "curious" if "curious" in conditions else conditions[0]
    if condition not in conditions:
        raise ValueError(f"condition {condition!r} not in the results; have {conditions}")
    return condition


def _one_run(episodes: pd.DataFrame, condition: str | None, run: int | None) -> tuple[str, int, pd.DataFrame]:
    condition = _condition(episodes, condition)
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
) -> Figure:
    """Figure 4D: the adaptive module's estimation error vs global step.

    The paper's "cumulative estimation error" is read as eq 11's context-wide error
    (accumulated over the context's states), not as a running sum over time.
    The error (eq 11 aggregate, column ``error``) is averaged per run over bins of
    ``bin_steps`` frames, then over runs (line ± sd band); one run (``run``, default the
    first) is overlaid at episode resolution. Two lines: the mean, the single run.
    """
    condition = _condition(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    _, run, single = _one_run(episodes, condition, run)
    with _style():
        fig, axes = _figure()
        ax = axes[0, 0]
        sns.lineplot(data=_binned(table, column, bin_steps), x="step", y=column, errorbar="sd",
                     ax=ax, label=f"mean over {table['run'].nunique()} runs (± sd)")
        ax.plot(single["step"], single[column], lw=0.6, alpha=0.6, color="0.3", label=f"run {run}")
        ax.set(xlabel="global step (frames)", ylabel="estimation error",
               title=f"Estimation error — {condition}")
        ax.legend(loc="upper right")
    return fig


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
    condition = _condition(episodes, condition)
    table = episodes[episodes["condition"] == condition]
    if not include_boredom:
        table = table[~table["familiar"].astype(bool)]
    mean = _binned(table, "da", bin_steps).groupby("step")["da"].mean()
    smooth = mean.rolling(window, center=True, min_periods=1).mean()
    with _style():
        fig, axes = _figure()
        ax = axes[0, 0]
        sns.lineplot(x=smooth.index, y=smooth.to_numpy(), ax=ax, errorbar=None)
        ax.axhline(0.0, color="0.5", lw=0.8, ls=":")
        note = "boredom −100 included" if include_boredom else "familiar episodes left out"
        if symlog:
            ax.set_yscale("symlog", linthresh=_progress_linthresh(table))
            note += "; symlog axis"
        if ylim is not None:
            ax.set_ylim(*ylim)
            note += f"; y clipped to [{ylim[0]:g}, {ylim[1]:g}]"
        ax.set(xlabel="global step (frames)", ylabel="intrinsic reward (DA)",
               title=f"Smoothed intrinsic reward — {condition} ({note})")
    return fig


def fig_learning_time(
    episodes: pd.DataFrame,
    modules: pd.DataFrame,
    condition: str | None = None,
    *,
    spec: SourceSpec = SYNTHETIC,
    since: str = "previous",
) -> Figure:
    """Figure 4F: learning time per learnable source in epochs, mean ± sd over runs.

    One bar per (source, condition) — all conditions unless ``condition`` is given — with
    the runs as points. Learning time as in :func:`neurocur.analysis.stats.learning_times`
    (first module of each source).
    """
    times = learning_times(episodes, modules, spec, since=since)
    times = times[times["learnable"] & times["first_of_source"]]
    conditions = sorted(episodes["condition"].unique())
    if condition is not None:
        conditions = [_condition(episodes, condition)]
    times = times[times["condition"].isin(conditions)]
    with _style():
        fig, axes = _figure()
        ax = axes[0, 0]
        if times.empty:
            ax.text(0.5, 0.5, "no learnable source was learned", ha="center", va="center",
                    transform=ax.transAxes)
        else:
            kwargs = dict(data=times, x="source", y="epochs", hue="condition", order=list(spec.learnable),
                          hue_order=conditions, ax=ax)
            sns.barplot(**kwargs, errorbar="sd", capsize=0.15, alpha=0.7)
            sns.stripplot(**kwargs, dodge=True, palette=["0.2"] * len(conditions), size=3, legend=False)
        ax.set(xlabel="source", ylabel="learning time (epochs)", title="Learning time per source (mean ± sd)")
    return fig


def _reward_estimates(run: pd.DataFrame, n_contexts: int, alpha: float | None) -> np.ndarray:
    """(n_episodes, n_contexts) running reward estimate of each context after each episode (eq 14).

    Episodes without a defined reward (NaN DA) leave the estimate unchanged.
    """
    if alpha is not None and not 0.0 < alpha <= 1.0:
        raise ValueError(f"alpha must be in (0, 1] or None for the sample average, got {alpha}")
    da = run["da"].to_numpy(dtype=float)
    contexts = run["context"].to_numpy()
    estimates = np.full((len(run), n_contexts), np.nan)
    for c in range(n_contexts):
        visits = (contexts == c) & np.isfinite(da)
        rewards = pd.Series(da[visits])
        if alpha is None:
            running = rewards.expanding().mean()
        else:  # R starts at 0: y_0 = 0, y_t = (1 - alpha) y_{t-1} + alpha x_t
            running = pd.concat([pd.Series([0.0]), rewards]).ewm(alpha=alpha, adjust=False).mean().iloc[1:]
        estimates[visits, c] = running.to_numpy()
    return pd.DataFrame(estimates).ffill().fillna(0.0).to_numpy()


def fig_reward_function(
    episodes: pd.DataFrame,
    run: int | None = None,
    condition: str | None = None,
    *,
    alpha: float | None = 0.1,
    symlog: bool = True,
    spec: SourceSpec = SYNTHETIC,
) -> Figure:
    """Figure 4G: the reward function per context over time, for one run.

    The running estimate of each context's intrinsic reward, recomputed from the episodes
    with eq 14 (learning rate ``alpha``, the PFC's; ``None``: sample average). One line per
    context of the world. With ``symlog`` the y-axis is linear only near zero (as in
    :func:`fig_neuromodulators`), so the rise of the learning-progress reward shows beside
    the boredom-driven drop.
    """
    condition, run, table = _one_run(episodes, condition, run)
    n_contexts = len(spec.context_names)
    if table["context"].max() >= n_contexts:
        raise ValueError(f"episodes visit context {table['context'].max()} but the world has {n_contexts}")
    estimates = _reward_estimates(table, n_contexts, alpha)
    steps = table["step"].to_numpy() + table["n_frames"].to_numpy()
    with _style():
        fig, axes = _figure()
        ax = axes[0, 0]
        palette = sns.color_palette("colorblind", n_contexts)
        for c, (name, source) in enumerate(zip(spec.context_names, spec.context_sources)):
            ax.plot(steps, estimates[:, c], drawstyle="steps-post", color=palette[c], label=f"{name} ({source})")
        rule = "sample average" if alpha is None else f"eq 14, α={alpha:g}"
        ax.set(xlabel="global step (frames)", ylabel="estimated reward R(context)",
               title=f"Reward function — {condition}, run {run} ({rule})")
        if symlog:
            ax.set_yscale("symlog", linthresh=_progress_linthresh(table))
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig


def fig_order_counts(
    modules: pd.DataFrame,
    episodes: pd.DataFrame | None = None,
    *,
    spec: SourceSpec = SYNTHETIC,
) -> Figure:
    """Which source was stored 1st/2nd/3rd, counted over runs; one panel per condition.

    Pass ``episodes`` so that runs without any module are counted (as "none"); without it
    the runs are those of the modules table.
    """
    if episodes is None:
        episodes = modules[["condition", "run"]].drop_duplicates().assign(episode=0, context=0, n_frames=0)
    counts = position_counts(episodes, modules, spec)
    conditions = sorted(counts["condition"].unique())
    sources = list(dict.fromkeys(counts["source"]))
    with _style():
        fig, axes = _figure(1, len(conditions), figsize=(4.0 * len(conditions), 3.8), sharey=True)
        for ax, condition in zip(axes[0], conditions):
            table = counts[counts["condition"] == condition]
            sns.barplot(data=table, x="position", y="k", hue="source", hue_order=sources, ax=ax,
                        palette="colorblind", legend=ax is axes[0, -1])
            ax.set(xlabel="storage position", ylabel="runs",
                   title=f"{condition} (n={int(table['n'].iloc[0])})")
    return fig


def fig_neuromodulators(
    episodes: pd.DataFrame,
    run: int | None = None,
    condition: str | None = None,
    *,
    da_linthresh: float | None = None,
) -> Figure:
    """DA, NE tonic, NE phasic and ε per episode for one run, module storage marked.

    Four stacked panels sharing the step axis; each has one trace plus a dashed vertical
    line (gid ``"module_learned"``) at every module storage. DA is drawn on a symlog axis
    (linear within ``±da_linthresh``, default the 90th percentile of |DA| on unfamiliar
    episodes) so the −100 boredom rewards and the small learning-progress rewards both show.
    """
    condition, run, table = _one_run(episodes, condition, run)
    steps = table["step"].to_numpy()
    events = (table["step"] + table["n_frames"])[table["module_learned"].astype(bool)].to_numpy()
    if da_linthresh is None:
        da_linthresh = _progress_linthresh(table)
    panels = (("da", "DA (intrinsic reward)"), ("ne_tonic", "NE tonic"),
              ("ne_phasic", "NE phasic"), ("epsilon", "ε"))
    with _style():
        fig, axes = _figure(len(panels), 1, figsize=(8.0, 7.0), sharex=True)
        palette = sns.color_palette("deep", len(panels))
        for ax, color, (column, label) in zip(axes[:, 0], palette, panels):
            ax.plot(steps, table[column].to_numpy(dtype=float), color=color, lw=0.8)
            for x in events:
                ax.axvline(x, color="0.3", ls="--", lw=0.8, gid=EVENT_GID)
            ax.set_ylabel(label)
        axes[0, 0].set_yscale("symlog", linthresh=da_linthresh)
        axes[0, 0].set_title(f"Neuromodulators — {condition}, run {run} (dashed: module stored)")
        axes[-1, 0].set_xlabel("global step (frames)")
    return fig


def write_all(results_dir: str | Path, out_dir: str | Path | None = None, *, dpi: int = 120) -> list[Path]:
    """Draw every figure of a results folder and save them as PNG in ``out_dir``.

    ``out_dir`` defaults to ``results_dir/figures``. Writes ``order_counts.png``,
    ``learning_time.png`` and, per condition, ``cumulative_error_<condition>.png``,
    ``intrinsic_reward_<condition>.png``, ``reward_function_<condition>.png`` and
    ``neuromodulators_<condition>.png`` (the latter two for the condition's first run).
    A results folder of the iCub world (``world.type = "icub"`` in its config.toml) gets
    the iCub figures instead (:func:`neurocur.analysis.icub.write_icub_figures`).
    Returns the written paths.
    """
    from neurocur.analysis.icub import results_world_type, write_icub_figures

    if results_world_type(results_dir) == "icub":
        return write_icub_figures(results_dir, out_dir, dpi=dpi)
    episodes, modules = load(results_dir)
    out = Path(results_dir) / "figures" if out_dir is None else Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {
        "order_counts": fig_order_counts(modules, episodes),
        "learning_time": fig_learning_time(episodes, modules),
    }
    for condition in sorted(episodes["condition"].unique()):
        figures[f"cumulative_error_{condition}"] = fig_cumulative_error(episodes, condition)
        figures[f"intrinsic_reward_{condition}"] = fig_intrinsic_reward(episodes, condition)
        figures[f"reward_function_{condition}"] = fig_reward_function(episodes, condition=condition)
        figures[f"neuromodulators_{condition}"] = fig_neuromodulators(episodes, condition=condition)
    return save_figures(figures, out, dpi)


def save_figures(figures: dict, out: Path, dpi: int) -> list[Path]:
    """Write each ``{name: Figure}`` as ``out/<name>.png``; return the paths in order."""
    paths = []
    for name, fig in figures.items():
        path = out / f"{name}.png"
        fig.savefig(path, dpi=dpi)
        paths.append(path)
    return paths
