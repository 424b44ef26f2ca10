"""Every figure of a results folder, written as PNG files (``neurocur figures DIR``).

The figures a folder gets depend on its world: a :class:`FigureSet` is registered per world
type in :data:`FIGURE_SETS`, as region and world types are (:class:`neurocur.registry.Registry`;
a third-party package adds one through the ``neurocur.figure_sets`` entry-point group)::

    @FIGURE_SETS.register("icub")
    class ICubFigures(FigureSet):
        def draw(self, results): ...

:func:`write_all` picks the set of the folder's world type (the conditions' ``world.type``
in ``config.toml``): a folder whose conditions all have one registered world type gets that
type's set, any other folder the :class:`StandardFigures` (paper Figures 4D–G). Beside the PNG
files it writes ``index.csv``: per file the paper figure it reproduces and what it shows, read from
the very figures it saved (:func:`~neurocur.analysis.figures.style.caption_of`), so the index names
every PNG written and only those.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from neurocur.analysis.io import order_tables
from neurocur.analysis.results import Results
from neurocur.analysis.stats.efficiency import censoring_horizon, efficiency_per_run
from neurocur.analysis.stats.order import sweep_columns
from neurocur.analysis.stats.report import paired_tests, reference_group
from neurocur.regions.hpc import HPCROC
from neurocur.registry import Registry
from neurocur.results.safeio import atomic_text

from .learning import fig_cumulative_error, fig_learning_time, fig_order_counts
from .neuro import fig_efficiency
from .reward import fig_intrinsic_reward, fig_neuromodulators, fig_reward_function
from .style import caption_of, save_figures
from .sweeps import fig_sweep_efficiency

__all__ = ["FIGURE_SETS", "INDEX", "FigureSet", "StandardFigures", "figure_set", "task_report", "write_figures",
           "write_all"]

#: The file ``write_all`` writes beside the figures: one row per PNG (file, paper_figure, what_it_shows).
INDEX = "index.csv"
#: What the synthetic world's figure set does not draw from the folder, and how to get it (``neurocur figures``
#: draws it with its own run unless ``--no-invariance``).
FIGURE_5 = ("Figure 5 (invariance, section 4.1.5) is drawn by its own run, not from a results folder: "
            "neurocur invariance invariance --out DIR")

#: The figure set of each world type.
FIGURE_SETS = Registry("figure set", "neurocur.figure_sets")


class FigureSet:
    """The figures of a results folder of one world type: :meth:`draw` returns them by file stem,
    :meth:`tables` the tables they show (written beside them as CSV; none by default) and
    :meth:`report` the statistics ``neurocur run`` prints instead of the module-learning summary
    ("" by default: that summary is printed)."""

    def draw(self, results: Results) -> dict[str, Figure]:
        raise NotImplementedError

    def tables(self, results: Results) -> dict[str, pd.DataFrame]:
        return {}

    def report(self, results: Results) -> pd.DataFrame | None:
        """The task's own statistics over runs, condition by condition, for a world whose task is not
        module learning (a canonical task: :func:`~neurocur.analysis.stats.validation.over_runs`):
        ``neurocur run`` prints it in place of the module-learning summary, and :func:`write_all`
        writes it as ``statistics.csv``. None by default: the folder's summary is the module-learning one."""
        return None

    def notes(self, results: Results) -> list[str]:
        """Lines to print after the figures: a paper figure this set does not draw and how to get it."""
        return []


@FIGURE_SETS.register("synthetic")
class StandardFigures(FigureSet):
    """Paper Figures 4D–G for any world: ``order_counts`` and ``learning_time``, per condition
    ``cumulative_error_<condition>``, ``intrinsic_reward_<condition>``,
    ``reward_function_<condition>`` and ``neuromodulators_<condition>`` (the latter two for the
    condition's first run; the reward function with the condition's own eq-14 ``alpha``), and
    ``sweep_efficiency`` for a sweep (:func:`~neurocur.analysis.figures.sweeps.fig_sweep_efficiency`:
    heatmaps by condition and sweep point), and ``efficiency`` when the experiment declares a control condition
    (:attr:`~neurocur.analysis.results.Results.control`): the reference against it,
    :func:`~neurocur.analysis.figures.neuro.fig_efficiency`."""

    def draw(self, results: Results) -> dict[str, Figure]:
        episodes = results.episodes
        figures = {"order_counts": fig_order_counts(results), "learning_time": fig_learning_time(results)}
        thresholds = results.region_param(HPCROC, "threshold")
        for condition in results.conditions:
            figures[f"cumulative_error_{condition}"] = fig_cumulative_error(
                episodes, condition, spec=results.spec_of(condition), threshold=thresholds.get(condition))
            figures[f"intrinsic_reward_{condition}"] = fig_intrinsic_reward(episodes, condition)
            figures[f"reward_function_{condition}"] = fig_reward_function(results, condition=condition)
            figures[f"neuromodulators_{condition}"] = fig_neuromodulators(episodes, condition=condition,
                                                                     captions=results.probe_docs(condition))
        if sweep_columns(episodes):
            figures["sweep_efficiency"] = fig_sweep_efficiency(efficiency_per_run(results))
        reference, control = results.reference, results.control
        if control is not None and reference != control and {reference, control} <= set(results.conditions):
            # the order table's efficiency family (neurocur.analysis.io.order_tables): the same p-values
            horizon = censoring_horizon(results)
            tests = paired_tests(reference_group(results, reference), reference, horizon=horizon)["efficiency"]
            figures["efficiency"] = fig_efficiency(efficiency_per_run(results, horizon=horizon), tests, reference,
                                                   control)
        return figures

    def tables(self, results: Results) -> dict[str, pd.DataFrame]:
        """A sweep's order table as ``neurocur run`` prints it (:func:`~neurocur.analysis.io.order_tables`,
        wide: a row per statistic, a column per condition and sweep point)."""
        if not sweep_columns(results.episodes):
            return {}
        return {"order_table": order_tables(results.path, tables=(results.episodes, results.modules)).reset_index()}

    def notes(self, results: Results) -> list[str]:
        return [FIGURE_5] if results.world_types == {"synthetic"} else []


def figure_set(results: Results) -> FigureSet:
    """The figure set of ``results``' world type (:class:`StandardFigures` unless one is registered).

    Parameters
    ----------
    results : Results
        A results folder's tables and config.

    Returns
    -------
    FigureSet
        A new instance of the set registered for the folder's one world type, else of ``StandardFigures``.
    """
    types = results.world_types
    if len(types) == 1 and (kind := types.pop()) in FIGURE_SETS:
        return FIGURE_SETS.get(kind)()
    return StandardFigures()


def task_report(results_dir: str | Path, *, tables: tuple[pd.DataFrame, pd.DataFrame] | None = None
                ) -> pd.DataFrame | None:
    """:meth:`FigureSet.report` of a results folder's figure set (None for a module-learning
    world); ``tables``: the folder's ``(episodes, modules)`` when already loaded.

    Parameters
    ----------
    results_dir : str or path
        A results folder written by ``neurocur run``.
    tables : (pandas.DataFrame, pandas.DataFrame) or None
        The folder's episodes and modules tables, already loaded; None reads them.

    Returns
    -------
    pandas.DataFrame or None
        The task's statistics over runs, or None when the folder's summary is the module-learning one.
    """
    results = Results.load(results_dir, tables=tables)
    return figure_set(results).report(results)


def write_figures(results_dir: str | Path, out_dir: str | Path | None = None, *, dpi: int = 120,
                  also: Callable[[Results, Path], Mapping[str, Figure]] | None = None
                  ) -> tuple[list[Path], list[str]]:
    """Draw every figure of a results folder and save them, with an index.

    Parameters
    ----------
    results_dir : str or Path
        A results folder written by ``neurocur run``.
    out_dir : str or Path, optional
        Where to write (default ``results_dir/figures``).
    dpi : int
        The PNGs' resolution.
    also : callable, optional
        ``also(results, out)`` returns more figures by file stem, drawn by the caller once the folder is
        loaded (the command's Figure 5, which a layer above analysis runs); saved and indexed with the others.

    Returns
    -------
    tuple of (list of Path, list of str)
        The written paths: the figures of the folder's world type (:class:`FigureSet`) as PNG, the tables
        they show as CSV (:meth:`FigureSet.tables`), the task's statistics over runs as ``statistics.csv``
        when the set has them (:meth:`FigureSet.report`), and :data:`INDEX` (a row per PNG saved: its
        ``file``, the ``paper_figure`` it reproduces and ``what_it_shows``, the caption each figure carries,
        :func:`~neurocur.analysis.figures.style.caption_of`); and the set's :meth:`~FigureSet.notes`.
    """
    results = Results.load(results_dir)
    out = Path(results_dir) / "figures" if out_dir is None else Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = figure_set(results)
    written = []
    report = figures.report(results)
    for name, table in {**figures.tables(results), **({} if report is None else {"statistics": report})}.items():
        atomic_text(out / f"{name}.csv", table.to_csv(index=False))
        written.append(out / f"{name}.csv")
    drawn = {**figures.draw(results), **({} if also is None else also(results, out))}
    pngs = save_figures(drawn, out, dpi)
    index = pd.DataFrame([{"file": path.name, **asdict(caption_of(fig))} for path, fig in zip(pngs, drawn.values())],
                         columns=["file", "paper_figure", "what_it_shows"])
    atomic_text(out / INDEX, index.to_csv(index=False))
    written.append(out / INDEX)
    return written + pngs, figures.notes(results)


def write_all(results_dir: str | Path, out_dir: str | Path | None = None, *, dpi: int = 120) -> list[Path]:
    """:func:`write_figures`' written paths: every figure of a results folder as PNG, the tables they
    show as CSV and :data:`INDEX`.

    Parameters
    ----------
    results_dir : str or path
        A results folder written by ``neurocur run``.
    out_dir : str or path or None
        Where to write; None for ``results_dir/figures``.
    dpi : int
        The PNGs' resolution.

    Returns
    -------
    list of path
        The files written.
    """
    return write_figures(results_dir, out_dir, dpi=dpi)[0]
