"""Yu & Dayan (2005, Neuron 46:681): the figure of the inferential Posner task with changing cue
identity and the figure set of ``posner`` worlds (docs/validation.md, section 4; the statistics are
:mod:`neurocur.analysis.stats.posner`)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from neurocur.analysis.results import Results
from neurocur.analysis.stats.posner import posner_by_validity, posner_per_run, posner_summary, with_blocks

from ..stats.validation import over_runs
from .sets import FIGURE_SETS, FigureSet
from .style import figure, style

__all__ = ["fig_posner", "PosnerFigures"]


def _trace(ax, episodes: pd.DataFrame, condition: str) -> None:
    ep = with_blocks(episodes[episodes["condition"] == condition])
    ep = ep[ep["run"] == ep["run"].min()]
    trial = ep["episode"].to_numpy()
    ax.plot(trial, 1.0 - ep["validity"].to_numpy(), color="0.4", lw=1.2, ls="--", label="1 - validity")
    ax.plot(trial, ep["ach"].to_numpy(), color="C0", lw=0.9, label="ACh = 1 - gamma*")
    ax.plot(trial, ep["ne"].to_numpy(), color="C3", lw=0.6, alpha=0.8, label="NE = 1 - lambda")
    for t in trial[ep["changed"].astype(bool).to_numpy()]:
        ax.axvline(t, color="k", lw=0.8)
    switched = ep["switched"].astype(bool).to_numpy()
    ax.plot(trial[switched], np.full(switched.sum(), 1.02), "v", ms=3, color="C3", label="switch (Y6)")
    ax.set_xlabel("trial (vertical lines: unsignalled changes of the relevant cue)")
    ax.set_ylabel("level")
    ax.set_ylim(-0.02, 1.06)
    ax.set_title(f"ACh and NE over one run ({condition})")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))


def fig_posner(episodes: pd.DataFrame, by_validity: pd.DataFrame, per_run: pd.DataFrame):
    """Top: ACh, NE and 1 - validity over the first run of the first condition, changes and switches
    marked. Bottom left: the validity effect (reaction time, invalid - valid) against the validity, per
    condition (mean over runs). Bottom middle: ACh against 1 - validity (the identity dashed).
    Bottom right: per condition, trials to adopt a new relevant cue and false switches per 1000 trials.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``posner`` world (the trace of the first condition's lowest-numbered run).
    by_validity : pandas.DataFrame
        ``neurocur.analysis.stats.posner.posner_by_validity`` of it.
    per_run : pandas.DataFrame
        ``neurocur.analysis.stats.posner.posner_per_run`` of it; its order of conditions is the figure's.

    Returns
    -------
    matplotlib.figure.Figure
        The trace on top, three panels below.
    """
    conditions = list(dict.fromkeys(per_run["condition"]))
    with style():
        fig, axes = figure(2, 3, figsize=(12.0, 7.5), gridspec_kw={"height_ratios": [1, 1.1]})
        grid = axes[0, 0].get_gridspec()
        for ax in axes[0]:
            ax.remove()
        _trace(fig.add_subplot(grid[0, :]), episodes, conditions[0])
        ax_ve, ax_ach, ax_adapt = axes[1]
        for i, condition in enumerate(conditions):
            mean = by_validity[by_validity["condition"] == condition].groupby("validity")[["validity_effect", "ach"]].mean()
            ax_ve.plot(mean.index, mean["validity_effect"], "o-", color=f"C{i}", label=condition)
            ax_ach.plot(1.0 - mean.index, mean["ach"], "o-", color=f"C{i}", label=condition)
        ax_ve.set_xlabel("validity of the relevant cue")
        ax_ve.set_ylabel("validity effect, rt invalid - valid (samples)")
        ax_ve.set_title("the validity effect")
        ax_ve.legend(fontsize=7)
        ax_ach.plot([0, 0.5], [0, 0.5], color="0.5", ls="--", lw=0.8)
        ax_ach.set_xlabel("1 - validity")
        ax_ach.set_ylabel("ACh, second half of the blocks")
        ax_ach.set_title("ACh reports expected uncertainty")
        x = np.arange(len(conditions))
        means = posner_summary(per_run).loc[conditions]
        ax_adapt.bar(x - 0.2, means["trials_to_adopt"], width=0.4, color="C0", label="trials to adopt a new cue")
        twin = ax_adapt.twinx()
        twin.bar(x + 0.2, means["false_switches"], width=0.4, color="C3", label="false switches / 1000 trials")
        twin.grid(False)
        ax_adapt.set_xticks(x, conditions, rotation=30, fontsize=7, ha="right")
        ax_adapt.set_ylabel("trials to adopt a new cue", color="C0")
        twin.set_ylabel("false switches / 1000 trials", color="C3")
        ax_adapt.set_title("NE: adapting to a change")
    return fig


@FIGURE_SETS.register("posner")
class PosnerFigures(FigureSet):
    """Yu & Dayan 2005: :func:`fig_posner`; the tables :func:`posner_per_run` (``validation``) and
    :func:`posner_by_validity` (``validation_by_validity``), and their means per condition printed
    by ``neurocur run`` (:meth:`report`)."""

    def tables(self, results: Results) -> dict[str, pd.DataFrame]:
        """The two tables, their conditions in the experiment's order (``config.toml``'s)."""
        episodes = results.episodes
        declared = list(results.config.get("conditions", {}))
        rank = {c: i for i, c in enumerate(declared + sorted(set(results.conditions) - set(declared)))}
        return {name: table.sort_values("condition", key=lambda c: c.map(rank), kind="stable").reset_index(drop=True)
                for name, table in (("validation", posner_per_run(episodes)),
                                    ("validation_by_validity", posner_by_validity(episodes)))}

    def draw(self, results: Results) -> dict[str, Figure]:
        tables = self.tables(results)
        return {"validation": fig_posner(results.episodes, tables["validation_by_validity"], tables["validation"])}

    def report(self, results: Results) -> pd.DataFrame:
        """Each condition's per-run statistics over runs (:func:`~neurocur.analysis.stats.validation.over_runs`);
        the per-validity table is ``validation_by_validity.csv``."""
        return over_runs(self.tables(results)["validation"])
