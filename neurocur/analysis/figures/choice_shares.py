"""Each option's share of free choices over time, and where each subject's shares peak
(:mod:`neurocur.analysis.stats.choice_shares`; docs/hypotheses.md, entry 16)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from neurocur.contract import require_columns

from .style import figure, style

__all__ = ["fig_choice_shares", "fig_peak_bins"]


def fig_choice_shares(summaries: Mapping[str, pd.DataFrame], options: Sequence[str], *,
                      trials_per_bin: int | None = None) -> Figure:
    """One panel per ``{group: share_summary table}``: each option's mean share per bin with its
    interval as a band; the x axis counts bins (or trials, given ``trials_per_bin``).

    Parameters
    ----------
    summaries : mapping of str to pandas.DataFrame
        ``{group: table}``, each table as ``neurocur.analysis.stats.choice_shares.share_summary`` returns it
        (columns ``bin``, ``option``, ``mean``, ``ci_low``, ``ci_high``, ``n``); one panel per group, in
        this order.
    options : sequence of str
        The options drawn, one line each, in legend order.
    trials_per_bin : int or None
        Trials in a bin: the x axis then counts trials (each bin at its last trial); None counts bins.

    Returns
    -------
    matplotlib.figure.Figure
        One row of panels sharing the share axis.
    """
    for summary in summaries.values():
        require_columns(summary, ["bin", "option", "mean", "ci_low", "ci_high", "n"], needed_by="fig_choice_shares")
    with style():
        fig, axes = figure(1, len(summaries), figsize=(4.2 * len(summaries), 3.4), sharey=True)
        for ax, (group, summary) in zip(axes[0], summaries.items()):
            for option in options:
                rows = summary[summary["option"] == option].sort_values("bin")
                x = rows["bin"] * trials_per_bin if trials_per_bin else rows["bin"]
                line, = ax.plot(x, rows["mean"], marker="o", markersize=3, linewidth=1.3, label=option)
                ax.fill_between(x, rows["ci_low"], rows["ci_high"], color=line.get_color(), alpha=0.2, linewidth=0)
            ax.set_title(f"{group} (n = {int(summary['n'].iloc[0])})", fontsize=10)
            ax.set_xlabel(f"free-play trial (end of each bin of {trials_per_bin})" if trials_per_bin else "bin")
        axes[0, 0].set_ylabel("share of choices (mean, 95 % CI)")
        axes[0, 0].legend(fontsize=8, loc="upper right")
    return fig


def fig_peak_bins(peaks: Mapping[str, np.ndarray], options: Sequence[str]) -> Figure:
    """One panel per ``{group: peak_bins array (subjects, options)}``: for each option, the
    distribution of the subjects' peak bins as a box (quartiles, whiskers to 1.5 IQR) with its
    mean as a diamond; subjects who never chose the option are left out (their count is printed).

    Parameters
    ----------
    peaks : mapping of str to numpy.ndarray
        ``{group: array}``, each of shape (subjects, options) as
        ``neurocur.analysis.stats.choice_shares.peak_bins`` returns it (NaN for an option never chosen); one
        panel per group, in this order.
    options : sequence of str
        The option names, in the arrays' column order (drawn top to bottom).

    Returns
    -------
    matplotlib.figure.Figure
        One row of panels sharing the bin axis.
    """
    with style():
        fig, axes = figure(1, len(peaks), figsize=(4.2 * len(peaks), 3.0), sharex=True)
        for ax, (group, peak) in zip(axes[0], peaks.items()):
            values = [peak[:, k][np.isfinite(peak[:, k])] for k in range(len(options))]
            y = np.arange(len(options))[::-1]
            ax.boxplot(values, positions=y, orientation="horizontal", widths=0.5, showmeans=True,
                       meanprops={"marker": "D", "markersize": 4})
            labels = [f"{option}\n({len(v)} of {peak.shape[0]})" for option, v in zip(options, values)]
            ax.set_yticks(y, labels, fontsize=8)
            ax.set_title(group, fontsize=10)
            ax.set_xlabel("bin of the largest share (ties: mean position)")
    return fig
