"""The neuromodulator models against the canonical results of their source papers: the figures
(docs/validation.md; the statistics are :mod:`neurocur.analysis.stats.validation`), and the figure
set of each canonical task's world type (``vigilance``, ``conditioning``, ``reward_blocks``): its
figure ``validation`` and the per-run table it shows, ``validation.csv``."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from neurocur.analysis.results import Results
from neurocur.analysis.stats.validation import (
    blocks_per_run,
    conditioning_per_run,
    disengaged,
    over_runs,
    vigilance_per_run,
)
from neurocur.contexts.reward_blocks import RewardBlocksParams

from .sets import FIGURE_SETS, FigureSet
from .style import figure, style

__all__ = ["fig_vigilance", "fig_conditioning", "fig_blocks", "fig_relearning", "VigilanceFigures",
           "ConditioningFigures", "RewardBlocksFigures"]


def fig_vigilance(episodes: pd.DataFrame, per_run: pd.DataFrame):
    """Left: the LC's baseline and its peak to targets and to distractors, per mode (bars, mean over
    runs; dots, runs). Right: hit rate, false-alarm rate and d' per mode.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table; not read (``per_run`` holds what is drawn).
    per_run : pandas.DataFrame
        ``neurocur.analysis.stats.validation.vigilance_per_run`` of the folder; its order of conditions is
        the figure's.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: the LC's response, and the performance.
    """
    with style():
        fig, axes = figure(1, 2, figsize=(9.0, 3.6))
        conditions = list(dict.fromkeys(per_run["condition"]))
        x = np.arange(len(conditions))
        for i, (column, label) in enumerate((("baseline", "baseline"), ("peak_target", "peak, targets"),
                                             ("peak_distractor", "peak, distractors"))):
            means = [per_run.loc[per_run["condition"] == c, column].mean() for c in conditions]
            axes[0, 0].bar(x + (i - 1) * 0.27, means, width=0.27, label=label)
        axes[0, 0].set_xticks(x, conditions)
        axes[0, 0].set_ylabel("LC activity h(v) = C v + (1 - C) d")
        axes[0, 0].set_title("LC response (Gilzenrat et al. 2002)")
        axes[0, 0].legend(fontsize=8)
        ax = axes[0, 1]
        for i, (column, label) in enumerate((("hit_rate", "hits"), ("false_alarm_rate", "false alarms"))):
            means = [per_run.loc[per_run["condition"] == c, column].mean() for c in conditions]
            ax.bar(x + (i - 0.5) * 0.35, means, width=0.35, label=label)
        ax.set_xticks(x, conditions)
        ax.set_ylabel("rate")
        twin = ax.twinx()
        twin.plot(x, [per_run.loc[per_run["condition"] == c, "d_prime"].mean() for c in conditions], "ko-", label="d'")
        twin.set_ylabel("d'")
        twin.grid(False)
        ax.set_title("performance")
        ax.legend(fontsize=8, loc="upper left")
        twin.legend(fontsize=8, loc="upper right")
    return fig


def fig_conditioning(episodes: pd.DataFrame):
    """DA at the cue and at the reward's time over training trials (mean over runs; omitted trials
    marked), the baseline, and the omission dip (Schultz et al. 1997, Fig. 1); a row per condition.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``conditioning`` world (columns ``episode``, ``omitted``, ``da_cue``,
        ``da_reward``, ``da_baseline``, and ``condition`` when it holds several).

    Returns
    -------
    matplotlib.figure.Figure
        Per condition (rows), two panels: DA over trials, and the three cases of their Fig. 1.
    """
    conditions = list(dict.fromkeys(episodes["condition"])) if "condition" in episodes else [None]
    with style():
        fig, axes = figure(len(conditions), 2, figsize=(9.0, 3.6 * len(conditions)),
                           gridspec_kw={"width_ratios": [2, 1]})
        for row, condition in enumerate(conditions):
            ep = episodes if condition is None else episodes[episodes["condition"] == condition]
            named = "" if len(conditions) == 1 else f"{condition}: "
            _conditioning_row(ep, axes[row, 0], axes[row, 1], named)
    return fig


def _conditioning_row(episodes: pd.DataFrame, ax, bars, named: str) -> None:
    """One condition's two panels of :func:`fig_conditioning`, titles led by ``named``."""
    rewarded = episodes[~episodes["omitted"].astype(bool)]
    for column, label in (("da_cue", "DA at the cue"), ("da_reward", "DA at the reward")):
        mean = rewarded.groupby("episode")[column].mean()
        ax.plot(mean.index, mean.to_numpy(), label=label)
    omitted = episodes[episodes["omitted"].astype(bool)]
    if len(omitted):
        ax.plot(omitted["episode"], omitted["da_reward"], "v", ms=3, color="C3", label="reward omitted")
    ax.axhline(float(episodes["da_baseline"].mean()), color="0.5", lw=0.8, ls="--", label="baseline")
    ax.set_xlabel("trial")
    ax.set_ylabel("DA = TD error (reward units)")
    ax.set_title(f"{named}DA moves from the reward to the cue")
    ax.legend(fontsize=8)
    late = episodes[episodes["episode"] >= episodes["episode"].max() * 0.6]
    groups = {"early, rewarded": episodes[(episodes["episode"] < 10) & ~episodes["omitted"].astype(bool)],
              "late, rewarded": late[~late["omitted"].astype(bool)], "late, omitted": late[late["omitted"].astype(bool)]}
    x = np.arange(len(groups))
    for i, (column, label) in enumerate((("da_cue", "cue"), ("da_reward", "reward time"))):
        bars.bar(x + (i - 0.5) * 0.35, [g[column].mean() if len(g) else np.nan for g in groups.values()],
                 width=0.35, label=label)
    bars.axhline(0.0, color="k", lw=0.8)
    bars.set_xticks(x, list(groups), rotation=20, fontsize=8)
    bars.set_title(f"{named}the three panels of their Fig. 1")
    bars.legend(fontsize=8)


def fig_blocks(episodes: pd.DataFrame, block_visits: int):
    """Per condition (rows): the reward, the LC's tonic drive and the share of disengage decisions
    over visits (moving averages of ``block_visits // 25`` visits, mean over runs), blocks marked.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``reward_blocks`` world (columns ``condition``, ``episode``, ``action``,
        ``reward``, ``ne_tonic``).
    block_visits : int
        Visits per block of the world, > 0.

    Returns
    -------
    matplotlib.figure.Figure
        A panel per condition, sharing the visit axis.
    """
    conditions = list(dict.fromkeys(episodes["condition"]))
    width = max(1, block_visits // 25)
    with style():
        fig, axes = figure(len(conditions), 1, figsize=(8.0, 2.6 * len(conditions)), sharex=True)
        for row, condition in enumerate(conditions):
            ep = episodes[episodes["condition"] == condition].copy()
            ep["disengaged"] = disengaged(ep).astype(float)
            mean = ep.groupby("episode")[["reward", "ne_tonic", "disengaged"]].mean()
            smooth = mean.rolling(width, min_periods=1).mean()
            ax = axes[row, 0]
            for column, label in (("reward", "utility (reward)"), ("ne_tonic", "LC tonic drive (1 - engagement)"),
                                  ("disengaged", "P(disengage)")):
                ax.plot(smooth.index, smooth[column].to_numpy(), label=label)
            for k in range(1, int(mean.index.max()) // block_visits + 1):
                ax.axvline(k * block_visits, color="0.5", lw=0.8, ls="--")
            ax.set_title(condition)
            ax.set_ylim(-0.05, 1.05)
            ax.legend(fontsize=8, loc="center right")
        axes[-1, 0].set_xlabel("visit")
    return fig


def fig_relearning(per_run: pd.DataFrame, a: str, b: str):
    """Frames from the swap to the first module of the swapped-in source, per run, ``b`` and ``a``
    side by side (a line joins the two runs of a seed; hollow markers: censored, not re-learned).

    Parameters
    ----------
    per_run : pandas.DataFrame
        ``neurocur.analysis.stats.validation.relearning_per_run`` of the folder.
    a : str
        The condition drawn right; it must have each of ``b``'s runs.
    b : str
        The condition drawn left, whose runs are paired.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: the two conditions' runs, joined by seed.
    """
    with style():
        fig, axes = figure(1, 1, figsize=(4.5, 3.8))
        ax = axes[0, 0]
        x = per_run[per_run["condition"] == b].set_index("run")
        y = per_run[per_run["condition"] == a].set_index("run").loc[x.index]
        for run in x.index:
            ax.plot([0, 1], [x.loc[run, "frames_to_relearn"] / 1e3, y.loc[run, "frames_to_relearn"] / 1e3],
                    color="0.6", lw=0.8)
        for i, t in enumerate((x, y)):
            done = t["relearned"].astype(bool)
            ax.plot(np.full(done.sum(), i), t["frames_to_relearn"][done] / 1e3, "o", color=f"C{i}")
            ax.plot(np.full((~done).sum(), i), t["frames_to_relearn"][~done] / 1e3, "o", mfc="none", color=f"C{i}")
        ax.set_xticks([0, 1], [b, a])
        ax.set_xlim(-0.4, 1.4)
        ax.set_ylabel("frames from the swap to re-learning (thousands)")
        ax.set_title("re-learning after the world changes")
    return fig


@FIGURE_SETS.register("vigilance")
class VigilanceFigures(FigureSet):
    """Gilzenrat et al. 2002: :func:`fig_vigilance` of :func:`vigilance_per_run`."""

    def tables(self, results: Results) -> dict[str, pd.DataFrame]:
        return {"validation": vigilance_per_run(results.episodes)}

    def draw(self, results: Results) -> dict[str, Figure]:
        return {"validation": fig_vigilance(results.episodes, self.tables(results)["validation"])}

    def report(self, results: Results) -> pd.DataFrame:
        return over_runs(self.tables(results)["validation"])


@FIGURE_SETS.register("conditioning")
class ConditioningFigures(FigureSet):
    """Schultz, Dayan & Montague 1997: :func:`fig_conditioning`, and :func:`conditioning_per_run`."""

    def tables(self, results: Results) -> dict[str, pd.DataFrame]:
        return {"validation": conditioning_per_run(results.episodes)}

    def draw(self, results: Results) -> dict[str, Figure]:
        return {"validation": fig_conditioning(results.episodes)}

    def report(self, results: Results) -> pd.DataFrame:
        return over_runs(self.tables(results)["validation"])


@FIGURE_SETS.register("reward_blocks")
class RewardBlocksFigures(FigureSet):
    """Aston-Jones & Cohen 2005: :func:`fig_blocks`, and :func:`blocks_per_run`, with the blocks'
    length from the world's ``block_visits`` (the world's default when the folder's config does not give it)."""

    @staticmethod
    def _block_visits(results: Results) -> int:
        default = next(f.default for f in dataclasses.fields(RewardBlocksParams) if f.name == "block_visits")
        worlds = list(results.world_tables.values())
        return int(worlds[0].get("block_visits", default)) if worlds else default

    def tables(self, results: Results) -> dict[str, pd.DataFrame]:
        return {"validation": blocks_per_run(results.episodes, self._block_visits(results))}

    def draw(self, results: Results) -> dict[str, Figure]:
        return {"validation": fig_blocks(results.episodes, self._block_visits(results))}

    def report(self, results: Results) -> pd.DataFrame:
        return over_runs(self.tables(results)["validation"], by=("condition", "block"))
