"""Reading a results folder for the analysis, and writing its ``summary.json``.

The folder belongs to :class:`neurocur.results.ResultsStore`; this module reads it
through the store (as a :class:`~neurocur.analysis.results.Results`). Nothing here rebuilds
a world or a circuit: what a condition's world showed (its contexts, their sources, the
learnable sources in Ω order) is in each run's ``run.json``.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from neurocur.contexts.base import SourceSpec
from neurocur.results import ResultsError, ResultsStore, load, run_dirs
from neurocur.results.runinfo import run_number

from .results import Results, source_specs
from .stats.efficiency import censoring_horizon
from .stats.folder_summary import summary
from .stats.report import of_the_paper, order_table, paired_test_rows, reference_group
from .stats.verdict import verdict_notes, verdict_table

__all__ = ["dataset", "load", "run_dirs", "source_specs", "order_tables", "narrow", "verdict_text", "throughput",
           "write_summary"]


def dataset(results_dir: str | Path, table: str = "episodes") -> ds.Dataset:
    """Every run's ``<table>.parquet`` of a results folder as one :class:`pyarrow.dataset.Dataset`,
    with ``condition`` and ``run`` as columns, so that a whole folder is read, filtered and
    aggregated in one line without loading it into pandas::

        analysis.dataset(DIR).to_table(filter=pyarrow.compute.field("run") == 0)
        duckdb.sql("SELECT condition, avg(da) FROM ds GROUP BY condition")  # ds = analysis.dataset(DIR)
        polars.scan_pyarrow_dataset(analysis.dataset(DIR, "modules"))

    ``table``: ``episodes`` (default), ``modules`` or a further table of the world type (iCub:
    ``features``). The run folders are those of :meth:`neurocur.results.ResultsStore.run_dirs`,
    with every check of the store: a folder that is not a results folder, a copied or renamed run
    folder, a ``run.json`` or a table that disagrees with ``config.toml`` or with its recorded
    sha256 are refused as :func:`load` refuses them; and each file's ``condition`` and ``run``
    must be its path's (ResultsError otherwise). A folder whose tables lack those columns
    (written before the tables carried them) is refused, naming :func:`load`, which reads it.
    The schema is every file's, unified (a column all null in one run takes another run's type).

    Parameters
    ----------
    results_dir : str or path
        The results folder.
    table : str
        The table's name.

    Returns
    -------
    pyarrow.dataset.Dataset
        Every run's file of the table.
    """
    folders = ResultsStore(results_dir).run_dirs()
    files = [folder / f"{table}.parquet" for folder in folders if (folder / f"{table}.parquet").is_file()]
    if not files:
        raise ValueError(f"{results_dir}: no run folder holds a table {table}.parquet")
    for path in files:
        _check_keys(path)
    schema = pa.unify_schemas([pq.read_schema(path) for path in files], promote_options="permissive")
    return ds.dataset([str(path) for path in files], schema=schema, format="parquet")


def _check_keys(path: Path) -> None:
    """ResultsError when the table ``path`` lacks ``condition`` or ``run`` or names another run than its path."""
    folder = path.parent
    if not {"condition", "run"} <= set(pq.read_schema(path).names):
        raise ResultsError(f"{path} has no 'condition' and 'run' columns (written by an older neurocur); "
                           "read this folder with neurocur.analysis.load")
    keys = pq.read_table(path, columns=["condition", "run"])
    conditions, runs = (pc.unique(keys[k]).to_pylist() for k in ("condition", "run"))
    condition, run = folder.parent.name, run_number(folder.name)
    if keys.num_rows and (conditions, runs) != ([condition], [run]):
        raise ResultsError(f"{path}: its 'condition' and 'run' columns say {conditions} and {runs}, not run {run} of "
                           f"{condition!r} as its path says (a copied or renamed folder?)")


def order_tables(
    results_dir: str | Path, conditions=None, *, reference: str | None = None, tests: bool = True,
    tables: tuple[pd.DataFrame, pd.DataFrame] | None = None, exclude_degenerate: bool = True,
) -> pd.DataFrame:
    """The order table (:func:`~neurocur.analysis.stats.report.order_table`) of every condition
    (or of ``conditions``), each with its own world's sources, side by side.

    With ``tests``, the rows of :func:`~neurocur.analysis.stats.report.paired_test_rows` follow: the
    paired tests of ``reference`` (default: the first condition of the folder's
    ``config.toml`` that has runs) against every other shown condition with the same world's
    sources, the efficiency metrics and the order metrics each Holm-adjusted as one family;
    each row names its test and adjustment; a degenerate condition (its runs repeat another's) is
    left out of them unless ``exclude_degenerate`` is false, and a row says so. The frames to learn all of every shown condition and
    their tests are censored at one cut-off, the shortest run of the shown conditions.
    ``tables``: the folder's ``(episodes, modules)`` when already loaded (:func:`load`), so that
    they are not read again.

    Parameters
    ----------
    results_dir : str or path
        The results folder.
    conditions : sequence of str, optional
        The conditions shown (default: all).
    reference : str, optional
        The tests' reference condition.
    tests : bool
        Add the paired tests' rows.
    tables : (pandas.DataFrame, pandas.DataFrame), optional
        The folder's ``(episodes, modules)`` when already loaded (:func:`load`), so that they are not read again.
    exclude_degenerate : bool
        Leave a degenerate condition out of the tests.

    Returns
    -------
    pandas.DataFrame
        A column per condition, a row per statistic (then the tests' rows).
    """
    results = Results.load(results_dir, tables=tables)
    specs = {c: s for c, s in results.specs.items() if conditions is None or c in conditions}
    horizon = censoring_horizon(results.select(specs))
    table = pd.concat([order_table(results.select([condition]), horizon=horizon) for condition in specs], axis=1)
    table = table.loc[:, ~table.columns.duplicated()]
    reference = next(iter(specs), None) if reference is None else reference
    if tests and reference in specs:
        group = reference_group(results.select(specs), reference)
        rows = paired_test_rows(group, reference, horizon=horizon, exclude_degenerate=exclude_degenerate)
        if len(rows):
            table = pd.concat([table, rows.reindex(columns=table.columns, fill_value="—")])
    return table


def verdict_text(results_dir: str | Path, conditions=None, *,
            tables: tuple[pd.DataFrame, pd.DataFrame] | None = None) -> str:
    """The verdict printed under the order table by ``neurocur run``: the reference condition against
    the experiment's control and the paper, per statistic (:func:`~neurocur.analysis.stats.verdict.verdict_table`,
    :func:`narrow`), then its rules and what each condition is (:func:`~neurocur.analysis.stats.verdict.verdict_notes`).
    Only the condition descriptions when the folder declares no control, or the reference or control is not
    among ``conditions`` (all by default) or their worlds differ. ``tables``: as in :func:`order_tables`.

    Parameters
    ----------
    results_dir : str or path
        The results folder.
    conditions : sequence of str, optional
        The conditions shown (default: all).
    tables : (pandas.DataFrame, pandas.DataFrame), optional
        The folder's ``(episodes, modules)`` when already loaded (:func:`load`), so that they are not read again.

    Returns
    -------
    str
        The verdict's lines.
    """
    results = Results.load(results_dir, tables=tables)
    if conditions is not None:
        results = results.select([c for c in results.conditions if c in conditions])
    reference, control = results.reference, results.control
    if (control is None or reference == control or not {reference, control} <= set(results.conditions)
            or results.spec_of(reference) != results.spec_of(control)):
        return "\n".join(verdict_notes(results, reference, reference)[2:])
    pair = results.select([reference, control])
    table = verdict_table(pair, reference, control, with_paper=of_the_paper(pair))
    title = f"verdict: {reference} against {control}" + (" and the paper" if "paper" in table else "")
    return "\n".join([title, narrow(table),
                      *verdict_notes(results, reference, control, n_tests=table.attrs["n_tests"])])


def narrow(table: pd.DataFrame, width: int = 100) -> str:
    """An order table as text no wider than ``width`` columns: each row's label, then its cells as
    ``column: value`` below it (the empty cells, "—", left out), indented, as many whole cells to a
    line as fit (a cell longer than the line stands alone). ``neurocur run`` prints it; the wide
    form is the table itself (:func:`order_tables`, e.g. ``order_tables(DIR).to_csv(path)``).

    Parameters
    ----------
    table : pandas.DataFrame
        An order table.
    width : int
        The widest line, in characters.

    Returns
    -------
    str
        The table's lines.
    """
    lines = []
    for label, row in table.iterrows():
        lines += textwrap.wrap(str(label), width, subsequent_indent="  ")
        line = ""
        for column, value in row.items():
            if value == "—":
                continue
            cell = f"{column}: {value}"
            if line and len(line) + 3 + len(cell) > width:
                lines.append(line)
                line = ""
            line = f"{line} · {cell}" if line else f"    {cell}"
        lines.append(line or "    —")
    return "\n".join(lines)


def write_summary(results_dir: str | Path, *, tables: tuple[pd.DataFrame, pd.DataFrame] | None = None) -> dict:
    """Aggregate every finished run into ``summary.json`` (:func:`~neurocur.analysis.stats.folder_summary.summary`).

    One summary when every condition's world has the same sources, else one per condition.
    The reference of the comparisons is the first condition of the folder's ``config.toml``
    (:attr:`~neurocur.analysis.results.Results.reference`). ``throughput`` records the runs' own
    compute time (``seconds`` of each ``run.json``, one core each): seconds per run and runs per
    core-hour. ``tables``: the folder's ``(episodes, modules)`` when already loaded (:func:`load`).

    Parameters
    ----------
    results_dir : str or path
        The results folder.
    tables : (pandas.DataFrame, pandas.DataFrame), optional
        The folder's ``(episodes, modules)`` when already loaded (:func:`load`), so that they are not read again.

    Returns
    -------
    dict
        What ``summary.json`` holds.
    """
    results = Results.load(results_dir, tables=tables)
    reference = results.reference
    if len(set(results.specs.values())) <= 1:
        result = {"spec": _spec_dict(next(iter(results.specs.values()))), **summary(results, reference=reference)}
    else:
        result = {"conditions": {}}
        for name, spec in results.specs.items():
            result["conditions"][name] = {"spec": _spec_dict(spec),
                                          **summary(results.select([name]), reference=reference)}
    result["throughput"] = throughput(results_dir)
    ResultsStore(results_dir).write_summary(result)
    return result


def throughput(results_dir: str | Path) -> dict:
    """Runs, mean seconds of one run (its own compute time, one core) and runs per core-hour.

    Parameters
    ----------
    results_dir : str or path
        The results folder.

    Returns
    -------
    dict
        ``runs``, ``seconds_per_run`` and ``runs_per_core_hour`` (None without a timed run).
    """
    store = ResultsStore(results_dir)
    seconds = [store.run_info(p).get("seconds") for p in store.run_dirs()]
    seconds = [s for s in seconds if isinstance(s, (int, float)) and s > 0]
    mean = sum(seconds) / len(seconds) if seconds else None
    return {"runs": len(seconds), "seconds_per_run": mean, "runs_per_core_hour": 3600.0 / mean if mean else None}


def _spec_dict(spec: SourceSpec) -> dict:
    return {"context_names": list(spec.context_names), "context_sources": list(spec.context_sources),
            "learnable": list(spec.learnable)}
