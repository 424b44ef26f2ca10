"""Axes and panel layout shared by the figures: readable symlog ticks (:func:`symlog_axis`) and
panels laid out by a sweep's swept values (:func:`panel_grid`)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

from neurocur.analysis.stats.sweeps import sweep_points

__all__ = ["symlog_axis", "panel_grid"]


def symlog_axis(ax, linthresh: float, *, max_ticks: int = 7) -> None:
    """A symlog y-axis, linear within ±``linthresh``, with readable ticks: 0 and ±10^k at whole
    decades from ``linthresh`` (or the decade below it, when above ``linthresh`` / 2) out to the data (every other decade when more than ``max_ticks``
    would show), labelled as plain numbers ("−100", "−1", "0.1"), never "−10⁰".

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes whose y-axis is set, after its data are drawn (the ticks reach the current y limits, which
        are kept).
    linthresh : float
        Half-width of the linear range around 0, > 0.
    max_ticks : int
        The most ticks shown before every other decade is dropped (the outermost decade is kept).
    """
    ax.set_yscale("symlog", linthresh=linthresh)
    low, high = ax.get_ylim()
    first = int(np.ceil(np.log10(linthresh)))
    first -= 10.0 ** (first - 1) >= linthresh / 2  # a decade inside the linear range, when far enough from 0
    last = int(np.floor(np.log10(max(abs(low), abs(high), linthresh))))
    decades = list(range(first, last + 1))
    ticks = [0.0, *(-10.0 ** k for k in decades if -10.0 ** k >= low), *(10.0 ** k for k in decades if 10.0 ** k <= high)]
    while len(ticks) > max_ticks and len(decades) > 1:
        decades = decades[::-2][::-1]  # every other decade, keeping the outermost
        ticks = [0.0, *(-10.0 ** k for k in decades if -10.0 ** k >= low),
                 *(10.0 ** k for k in decades if 10.0 ** k <= high)]
    ax.yaxis.set_major_locator(FixedLocator(sorted(ticks)))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}".replace("-", "−")))
    ax.set_ylim(low, high)


def panel_grid(table: pd.DataFrame, conditions: list[str], wrap: int) -> list[list[str | None]]:
    """The conditions laid out as rows of panels: by base condition and sweep point in a sweep
    (a point a base lacks is None), else in rows of ``wrap``.

    Parameters
    ----------
    table : pandas.DataFrame
        A table with a ``condition`` column and the sweep's columns
        (``neurocur.analysis.stats.sweeps.sweep_points`` reads them).
    conditions : list of str
        The conditions to lay out, in the order used when there is no sweep.
    wrap : int
        Panels per row when there is no sweep.

    Returns
    -------
    list of list of str or None
        Rows of panels: in a sweep, one row per base condition (in the order of the conditions' names) and
        one column per sweep point (in the order of the swept values); else ``conditions`` in rows of
        ``wrap``.
    """
    points = sweep_points(table[table["condition"].isin(conditions)])
    swept = [c for c in points.columns if c not in ("condition", "base", "point")]
    if not swept or points["point"].eq("").all():
        return [conditions[i:i + wrap] for i in range(0, len(conditions), wrap)]
    points = points.sort_values(swept, kind="stable")
    labels = list(dict.fromkeys(points["point"]))
    bases = list(dict.fromkeys(points.sort_values("condition")["base"]))
    named = dict(zip(zip(points["base"], points["point"]), points["condition"]))
    return [[named.get((base, label)) for label in labels] for base in bases]
