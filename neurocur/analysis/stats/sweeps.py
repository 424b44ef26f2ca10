"""Comparisons across a grid sweep, paired by run and adjusted for multiple comparisons.

A sweep runs every condition at every point of its grid, each point as a condition named
``<condition>@KEY=value,KEY=value`` (the point's *label*), with one column per swept key in
every results table (:func:`~neurocur.analysis.stats.order.sweep_columns`, carried into
:func:`~neurocur.analysis.stats.order.per_run`). Run *i* of every condition and point uses the
same seed, so two points (or two conditions at one point) are compared run by run
(:func:`~neurocur.analysis.stats.comparison.compare`, paired by default), and the p-values of the
whole output table are adjusted together (:func:`~neurocur.analysis.stats.comparison.adjust_pvalues`:
Holm 1979 by default, or Benjamini & Hochberg 1995).

* :func:`compare_to_point`: every point of a condition against a reference point of the same
  condition ("does moving LC.gain away from 1.0 change the order?");
* :func:`compare_to_condition`: every condition against a reference condition at the same
  point ("at each LC.gain, is curiosity better than random switching?").

Both take a per-run table (:func:`~neurocur.analysis.stats.order.per_run`) and return a tidy table: ``condition`` (the base name of ``b``), ``point`` (the label of
``b``'s point, "" without a sweep), the swept keys (``b``'s values), then
:data:`~neurocur.analysis.stats.comparison.COMPARE_COLUMNS`. The reference is always ``a``:
``difference`` and the effects are positive when the reference is higher.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd

from .bootstrap import BOOTSTRAP_SEED, N_BOOT
from .comparison import COMPARE_COLUMNS, adjust_pvalues, compare
from .order import sweep_columns

__all__ = ["split_condition", "sweep_points", "compare_to_point", "compare_to_condition"]


def split_condition(name: str) -> tuple[str, str]:
    """``"A@LC.gain=0.5"`` → ``("A", "LC.gain=0.5")``; ``"A"`` → ``("A", "")``.

    Parameters
    ----------
    name : str
        A condition's name, with or without a sweep point.

    Returns
    -------
    tuple of str
        The base name and the point's label (``""`` without ``@``).
    """
    base, _, label = str(name).partition("@")
    return base, label


def sweep_points(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per condition of a per-run table: condition, base, point (label), the swept keys' values.

    Parameters
    ----------
    runs : pandas.DataFrame
        A per-run table with ``condition`` (and the swept keys' columns of a sweep).

    Returns
    -------
    pandas.DataFrame
        One row per condition, in order of first appearance.
    """
    swept = sweep_columns(runs)
    names = list(dict.fromkeys(runs["condition"]))
    table = pd.DataFrame({"condition": names, "base": [split_condition(n)[0] for n in names],
                          "point": [split_condition(n)[1] for n in names]})
    if swept:
        values = runs.groupby("condition", sort=False)[swept].first()
        table = table.join(values, on="condition")
    return table


def _matches(row: pd.Series, reference, swept: list[str]) -> bool:
    if isinstance(reference, Mapping):
        return all(key in swept and row[key] == value for key, value in reference.items())
    return row["point"] == str(reference)


def _finish(tables: list[pd.DataFrame], swept: list[str], adjust) -> pd.DataFrame:
    columns = ["condition", "point", *swept, *COMPARE_COLUMNS]
    if not tables:
        return pd.DataFrame(columns=columns)
    return adjust_pvalues(pd.concat(tables, ignore_index=True), adjust)[columns]


def _compare_rows(runs, a, b_row, swept, metric, options) -> pd.DataFrame:
    table = compare(runs, a, b_row["condition"], metric, adjust=None, **options)
    table.insert(0, "condition", b_row["base"])
    table.insert(1, "point", b_row["point"])
    for i, key in enumerate(swept):
        table.insert(2 + i, key, b_row[key])
    return table


def compare_to_point(
    runs: pd.DataFrame,
    reference: Mapping | str,
    metric: str | Sequence[str] | None = None,
    *,
    conditions: Sequence[str] | None = None,
    paired: bool = True,
    adjust: str | None = "holm",
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """Every sweep point of each condition (``a`` = its reference point) against the reference point.

    ``reference``: the reference point, as ``{swept key: value}`` (matched against the swept
    columns; keys not given may take any value) or as its label ``"KEY=value,KEY=value"`` (as
    in the condition names). ``conditions``: the base names to compare (default: every one
    with exactly one reference point). One row per (condition, point, metric), adjusted
    together (``adjust``); see the module docstring for the columns.

    Parameters
    ----------
    runs : pandas.DataFrame
        Per-run metrics, one row per (condition, run), with the swept keys' columns.
    reference : mapping or str
        The reference point: ``{swept key: value}`` or its label.
    metric : str or sequence of str, optional
        The metrics tested, as in ``compare`` (default: every numeric and yes/no metric of
        ``per_run``).
    conditions : sequence of str, optional
        The base names compared (default: every one with the reference point).
    paired : bool
        Pair the runs by ``run`` (the default) or test them as independent samples.
    adjust : str or None
        The adjustment of ``p_value`` over the whole output table (``"holm"``, ``"bh"`` /
        ``"fdr_bh"``, ``"none"`` or None), as in ``adjust_pvalues``.
    n_boot : int
        The bootstrap resamples of each interval.
    confidence : float
        The intervals' coverage, in (0, 1).
    seed : int
        The bootstrap's seed.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, point, metric); empty (with its columns) when no condition has a
        point besides the reference.

    Raises
    ------
    ValueError
        When a key of ``reference`` is not swept, a condition of ``conditions`` is unknown or
        lacks the reference point, a condition has more than one point matching ``reference``,
        or none has it.
    """
    swept = sweep_columns(runs)
    if isinstance(reference, Mapping) and (missing := [k for k in reference if k not in swept]):
        raise ValueError(f"compare_to_point: {missing} not swept; the swept columns are {swept}")
    points = sweep_points(runs)
    bases = list(dict.fromkeys(points["base"])) if conditions is None else list(conditions)
    options = {"paired": paired, "n_boot": n_boot, "confidence": confidence, "seed": seed}
    tables, matched = [], 0
    for base in bases:
        mine = points[points["base"] == base]
        if mine.empty:
            raise ValueError(f"compare_to_point: no condition {base!r}; have {sorted(set(points['base']))}")
        ref = mine[[_matches(row, reference, swept) for _, row in mine.iterrows()]]
        if ref.empty and conditions is None:
            continue
        if len(ref) != 1:
            raise ValueError(f"compare_to_point: {len(ref)} points of {base!r} match {reference!r}; "
                             f"its points are {mine['point'].tolist()}")
        matched += 1
        a = ref["condition"].iloc[0]
        tables += [_compare_rows(runs, a, row, swept, metric, options)
                   for _, row in mine.iterrows() if row["condition"] != a]
    if not matched:
        raise ValueError(f"compare_to_point: no condition has the point {reference!r}; "
                         f"the points are {sorted(set(points['point']))}")
    return _finish(tables, swept, adjust)


def compare_to_condition(
    runs: pd.DataFrame,
    reference: str,
    metric: str | Sequence[str] | None = None,
    *,
    others: Sequence[str] | None = None,
    paired: bool = True,
    adjust: str | None = "holm",
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """Every other condition against ``reference`` (``a``) at the same sweep point.

    ``reference`` and ``others`` are base condition names (before the ``@``); ``others``
    defaults to every other base condition. At each point of ``reference``, every other
    condition run at that point is compared with it; a point one of them lacks is skipped.
    One row per (condition, point, metric), adjusted together (``adjust``); see the module
    docstring for the columns.

    Parameters
    ----------
    runs : pandas.DataFrame
        Per-run metrics, one row per (condition, run), with the swept keys' columns.
    reference : str
        The base name of the reference condition.
    metric : str or sequence of str, optional
        The metrics tested, as in ``compare`` (default: every numeric and yes/no metric of
        ``per_run``).
    others : sequence of str, optional
        The base names compared with it (default: every other).
    paired : bool
        Pair the runs by ``run`` (the default) or test them as independent samples.
    adjust : str or None
        The adjustment of ``p_value`` over the whole output table (``"holm"``, ``"bh"`` /
        ``"fdr_bh"``, ``"none"`` or None), as in ``adjust_pvalues``.
    n_boot : int
        The bootstrap resamples of each interval.
    confidence : float
        The intervals' coverage, in (0, 1).
    seed : int
        The bootstrap's seed.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, point, metric); empty (with its columns) when nothing is compared.

    Raises
    ------
    ValueError
        When ``reference`` or a name of ``others`` is not a base condition of ``runs``.
    """
    swept = sweep_columns(runs)
    points = sweep_points(runs)
    if reference not in set(points["base"]):
        raise ValueError(f"compare_to_condition: no condition {reference!r}; have {sorted(set(points['base']))}")
    bases = [b for b in dict.fromkeys(points["base"]) if b != reference] if others is None else list(others)
    if unknown := [b for b in bases if b not in set(points["base"])]:
        raise ValueError(f"compare_to_condition: no condition {unknown}; have {sorted(set(points['base']))}")
    options = {"paired": paired, "n_boot": n_boot, "confidence": confidence, "seed": seed}
    tables = []
    for _, ref in points[points["base"] == reference].iterrows():
        at = points[(points["point"] == ref["point"]) & points["base"].isin(bases)]
        tables += [_compare_rows(runs, ref["condition"], row, swept, metric, options) for _, row in at.iterrows()]
    return _finish(tables, swept, adjust)
