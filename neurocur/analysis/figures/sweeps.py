"""A sweep's results laid out by its swept values: heatmaps of the per-run efficiency.

:func:`fig_sweep_efficiency` draws, for every condition at every sweep point, the share of runs that
learned every learnable source and the mean frames until then (censored at the shortest run, the
restricted mean of :mod:`~neurocur.analysis.stats.efficiency`): a row per base condition, a column
per sweep point in the order of the swept values (:func:`~neurocur.analysis.figures.layout.panel_grid`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.figure import Figure

from neurocur.analysis.stats.sweeps import split_condition
from neurocur.contract import require_columns

from .layout import panel_grid
from .style import caption, figure, style

__all__ = ["SWEEP_METRICS", "sweep_matrix", "fig_sweep_efficiency"]

#: The metrics of :func:`fig_sweep_efficiency`: column of the efficiency table -> (title, cell text, colour range).
SWEEP_METRICS = {
    "learned_all": ("share of runs that learned all", "{:.2f}".format, (0.0, 1.0)),
    "frames_to_learn_all_censored": ("frames to learn all\n(mean, censored at the shortest run)",
                                     lambda v: f"{v / 1000:.1f}k", (None, None)),
}


def sweep_matrix(table: pd.DataFrame, metric: str) -> pd.DataFrame:
    """The mean of ``metric`` over each condition's runs of the per-run ``table`` (e.g.
    :func:`~neurocur.analysis.stats.efficiency.efficiency_per_run`), as a matrix: a row per base
    condition, a column per sweep point (its label, in the order of the swept values); NaN where a
    base condition lacks the point.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per run, with ``condition``, the sweep's columns and ``metric``.
    metric : str
        The column averaged.

    Returns
    -------
    pandas.DataFrame
        The means, indexed by base condition (``condition``), a column per sweep point (``point``).
    """
    require_columns(table, ["condition", metric], needed_by="sweep_matrix")
    means = table.groupby("condition")[metric].mean()
    grid = panel_grid(table, sorted(means.index), wrap=len(means))
    labels = [next(split_condition(c)[1] for c in column if c is not None) for column in zip(*grid)]
    bases = [next(split_condition(c)[0] for c in row if c is not None) for row in grid]
    values = [[means[c] if c is not None else np.nan for c in row] for row in grid]
    return pd.DataFrame(values, index=pd.Index(bases, name="condition"), columns=pd.Index(labels, name="point"))


def fig_sweep_efficiency(table: pd.DataFrame) -> Figure:
    """Heatmaps of :data:`SWEEP_METRICS` over a sweep's conditions and points (:func:`sweep_matrix`),
    each cell annotated with its value; ``table``: :func:`~neurocur.analysis.stats.efficiency.efficiency_per_run`.

    Parameters
    ----------
    table : pandas.DataFrame
        The efficiency per run of a sweep's results (columns ``condition``, ``run``, ``learned_all``,
        ``frames_to_learn_all_censored`` and the sweep's).

    Returns
    -------
    matplotlib.figure.Figure
        A heatmap per metric, side by side.
    """
    require_columns(table, ["condition", "run", *SWEEP_METRICS], needed_by="fig_sweep_efficiency")
    matrices = {metric: sweep_matrix(table.astype({"learned_all": float}), metric) for metric in SWEEP_METRICS}
    rows, columns = next(iter(matrices.values())).shape
    with style():
        fig, axes = figure(1, len(matrices), figsize=(len(matrices) * (1.6 * columns + 2.6), 1.0 * rows + 2.0))
        for ax, (metric, matrix) in zip(axes[0], matrices.items()):
            title, text, (low, high) = SWEEP_METRICS[metric]
            sns.heatmap(matrix, annot=matrix.map(lambda v, text=text: "—" if np.isnan(v) else text(v)), fmt="", cmap="viridis",
                        vmin=low, vmax=high, ax=ax, cbar=False)
            ax.set(title=f"{title} ({table['run'].nunique()} runs)", xlabel="sweep point", ylabel="condition")
            ax.tick_params(axis="y", labelrotation=0)
    return caption(fig, "none: a sweep of the model's parameters",
                   "per condition and sweep point: the share of runs that learned every learnable source and the "
                   "mean frames until then")
