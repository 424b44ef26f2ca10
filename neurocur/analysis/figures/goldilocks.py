"""The Goldilocks figure: engagement against learnability (:mod:`neurocur.analysis.stats.goldilocks`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from neurocur.analysis.stats.goldilocks import OUTCOMES
from neurocur.analysis.stats.inverted_u import level_means
from neurocur.contract import require_columns

from .style import figure, style

__all__ = ["fig_goldilocks"]


def fig_goldilocks(table: pd.DataFrame, outcomes: Sequence[str] = tuple(OUTCOMES)) -> Figure:
    """Each outcome per context, the contexts in order of learnability level: per condition the
    mean over runs with its 95 % t interval (one panel per outcome); the x ticks name each
    context's source and Ω (or "redrawn").

    Parameters
    ----------
    table : pandas.DataFrame
        One row per run and context, as
        ``neurocur.analysis.stats.goldilocks.engagement_by_learnability`` returns it: columns ``condition``,
        ``context``, ``level``, ``omega``, ``redrawn`` and each outcome (``source`` names the ticks when
        present).
    outcomes : sequence of str
        The outcome columns, one panel each (the keys of ``OUTCOMES`` by default: share of frames and mean
        dwell per visit, labelled from it; another column is labelled with its name).

    Returns
    -------
    matplotlib.figure.Figure
        The panels, stacked on a shared context axis.

    Raises
    ------
    ValueError
        When ``table`` lacks a column it reads (``neurocur.contract.require_columns``).
    """
    require_columns(table, ["condition", "context", "level", "omega", "redrawn", *outcomes], needed_by="fig_goldilocks")
    contexts = table.drop_duplicates("context").sort_values(["level", "context"])
    position = pd.Series(np.arange(len(contexts)), index=contexts["context"].to_numpy())
    table = table.assign(position=table["context"].map(position))
    labels = [f"{row.source if 'source' in contexts else row.context}\n"
              + ("redrawn" if row.redrawn else f"Ω {row.omega:.5f}") for row in contexts.itertuples()]
    conditions = list(dict.fromkeys(table["condition"]))
    width = 0.6 / max(len(conditions), 1)
    with style():
        fig, axes = figure(len(outcomes), 1, figsize=(9.0, 3.2 * len(outcomes)), sharex=True)
        for ax, outcome in zip(axes[:, 0], outcomes):
            means = level_means(table, "position", outcome, by="condition")
            for i, condition in enumerate(conditions):
                rows = means[means["condition"] == condition]
                x = rows["position"] + (i - (len(conditions) - 1) / 2) * width
                ax.errorbar(x, rows["mean"], yerr=[rows["mean"] - rows["ci_low"], rows["ci_high"] - rows["mean"]],
                            marker="o", markersize=4, capsize=2, linewidth=1.2, label=condition)
            ax.set_ylabel(OUTCOMES.get(outcome, outcome))
        axes[-1, 0].set_xticks(position.to_numpy(), labels, fontsize=8)
        axes[-1, 0].set_xlabel("context, in order of learnability (Ω, eq 40; easiest left)")
        axes[0, 0].legend(fontsize=7, ncols=min(len(conditions), 4), loc="upper left")
    return fig
