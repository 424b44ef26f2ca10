"""Reading a results folder back: its run folders, each checked against its path, and their tables joined.

**The folder is the truth.** A run's condition and number are those of its path
``runs/<condition>/run-<NNN>``; the ``condition`` and ``run`` of its ``run.json`` and of its
tables must agree, else reading (and resuming) fails naming the folder, what its files say
and, when the same run also exists under its own name, both paths (a copied or renamed
folder). A run folder is spelled ``run-<NNN>`` and is a real folder, and its ``run.json``
agrees with ``config.toml`` (seed, steps) and with its tables (sha256)
(:func:`~neurocur.results.runinfo.check_run_info`); a folder with runs but no ``config.toml``
is refused. :class:`~neurocur.results.ResultsStore` reads through these functions
(``run_dirs``, ``load``, ``load_table``) and checks each complete run the same way before it resumes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

import pandas as pd

from neurocur.config import ConfigError

from .configfile import CONFIG, folder_config
from .errors import ResultsError
from .runinfo import RUN_INFO, check_run_info, read_run_info, run_number, run_path, scan_runs

__all__ = ["check_run_folder", "join_runs", "join_table", "read_table", "run_folders"]

#: the tables every run folder holds
RUN_TABLES = ("episodes", "modules")


def run_folders(root: Path) -> list[Path]:
    """The run folders ``runs/<condition>/run-<NNN>`` of a results folder, sorted, each checked.

    Parameters
    ----------
    root : path
        The results folder.

    Returns
    -------
    list of path
        The run folders.

    Raises
    ------
    ValueError
        When ``root`` is not a results folder: no ``runs/`` folder, no run folder in it, or a
        run folder without its Parquet tables.
    ResultsError
        For a folder without its ``config.toml``, a run folder spelled otherwise than
        ``run-<NNN>`` or that is a link, without its ``run.json``, or that fails
        [`check_run_folder`][neurocur.results.reading.check_run_folder].
    """
    runs = root / "runs"
    if not root.is_dir():
        raise ValueError(f"results folder {root} does not exist or is not a directory")
    if not runs.is_dir():
        raise ValueError(f"{root} is not a results folder: expected a 'runs/' folder holding "
                         "runs/<condition>/run-<NNN>/episodes.parquet (write one with 'neurocur run')")
    found = scan_runs(runs)
    if not found:
        raise ValueError(f"{root} is not a results folder: 'runs/' holds no run folder runs/<condition>/run-<NNN>/")
    config = folder_config(root)
    for path in found:
        missing = [f"{name}.parquet" for name in RUN_TABLES if not (path / f"{name}.parquet").is_file()]
        if missing:
            raise ValueError(f"run folder {path} lacks {', '.join(missing)}")
        if config is None:
            raise ResultsError(f"{root} holds runs but no {CONFIG}, so nothing tells which experiment they "
                               f"belong to (a folder moved while it ran?); restore its {CONFIG}")
        if not (path / RUN_INFO).is_file():
            raise ResultsError(f"run folder {path} is incomplete: it lacks {RUN_INFO} "
                               "('neurocur run' into this folder computes it again)")
        check_run_folder(path, config)
    return found


def check_run_folder(run_folder: Path, config: Mapping | None) -> None:
    """Refuse a run folder whose ``run.json`` names another condition or run than its path, or
    disagrees with ``config`` (:func:`~neurocur.results.runinfo.check_run_info`).

    Parameters
    ----------
    run_folder : path
        A complete run folder ``runs/<condition>/run-<NNN>`` (one with its ``run.json``).
    config : mapping or None
        The results folder's ``config.toml`` as read.

    Raises
    ------
    ResultsError
        Naming the folder and what its ``run.json`` says (and the run's own folder, when it exists).
    """
    said = check_run_info(run_folder, read_run_info(run_folder), run_folder.parent.name,
                          _run_number(run_folder), config)
    if said is not None:
        raise _mismatch(run_folder, RUN_INFO, *said)


def read_table(run_folder: Path, name: str) -> pd.DataFrame:
    """A run's table ``<name>.parquet``, led by its ``condition`` and ``run``.

    Parameters
    ----------
    run_folder : path
        The run folder ``runs/<condition>/run-<NNN>``.
    name : str
        The table's name (``episodes``, ``modules``, or one of the world type's).

    Returns
    -------
    pandas.DataFrame
        The table; ``condition`` and ``run`` are taken from the folder's path when it lacks them.

    Raises
    ------
    ResultsError
        When the table's ``condition`` or ``run`` differ from its folder's path.
    """
    table = pd.read_parquet(run_folder / f"{name}.parquet")
    condition, run = run_folder.parent.name, _run_number(run_folder)
    said = {}
    for position, (column, value) in enumerate((("condition", condition), ("run", run))):
        if column not in table:
            table.insert(position, column, value)
        elif len(table):
            values = [v.item() if hasattr(v, "item") else v for v in table[column].unique()]
            said[column] = values[0] if len(values) == 1 else ", ".join(map(str, values))
    if said and (said.get("condition", condition), said.get("run", run)) != (condition, run):
        raise _mismatch(run_folder, f"{name}.parquet", said.get("condition", condition), said.get("run", run))
    return table


def join_runs(run_folders: Iterable[Path]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``(episodes, modules)`` of the given run folders as two tables, led by ``condition`` and ``run``.

    Sorted by condition, run and episode (modules: by condition, run and module rank); the
    modules' ``gates`` column is normalised to a (possibly empty) string.

    Parameters
    ----------
    run_folders : iterable of path
        Checked run folders ([`run_folders`][neurocur.results.reading.run_folders]), at least one.

    Returns
    -------
    (pandas.DataFrame, pandas.DataFrame)
        The episodes and modules tables ([`read_table`][neurocur.results.reading.read_table] of each run).
    """
    dirs = list(run_folders)
    episodes = pd.concat([read_table(p, "episodes") for p in dirs], ignore_index=True)
    modules = [read_table(p, "modules") for p in dirs]
    modules = pd.concat([m for m in modules if len(m)] or modules[:1], ignore_index=True)
    if "gates" in modules:
        modules["gates"] = modules["gates"].fillna("").astype(str)
    episodes = episodes.sort_values(["condition", "run", "episode"], kind="stable")
    modules = modules.sort_values(["condition", "run", "module"], kind="stable")
    return episodes.reset_index(drop=True), modules.reset_index(drop=True)


def join_table(run_folders: Iterable[Path], name: str, columns: Iterable[str] = ()) -> pd.DataFrame:
    """Every given run's ``<name>.parquet`` as one table.

    Parameters
    ----------
    run_folders : iterable of path
        Checked run folders; those without the table are skipped.
    name : str
        The table's name (iCub: ``features``).
    columns : iterable of str
        The columns of the empty table returned when no run has a non-empty one.

    Returns
    -------
    pandas.DataFrame
        The runs' tables concatenated in the order of ``run_folders``.
    """
    tables = [read_table(p, name) for p in run_folders if (p / f"{name}.parquet").is_file()]
    tables = [t for t in tables if len(t)]
    if not tables:
        return pd.DataFrame(columns=list(columns))
    return pd.concat(tables, ignore_index=True)


def _run_number(run_folder: Path) -> int:
    number = run_number(run_folder.name)
    if number is None:
        raise ResultsError(f"run folder {run_folder} is not named run-<NNN>")
    return number


def _mismatch(run_folder: Path, file: str, condition, run) -> ResultsError:
    """The error for a run folder whose ``file`` says it holds run ``run`` of ``condition``."""
    text = (f"run folder {run_folder} holds run {run} of condition {condition!r} by its {file}, not run "
            f"{_run_number(run_folder)} of {run_folder.parent.name!r} as its path says (a copied or renamed folder?)")
    try:
        own = (run_path(run_folder.parent.parent, str(condition), run)
               if isinstance(run, int) and not isinstance(run, bool) else None)
    except ConfigError:  # its files name a condition that is no folder name
        own = None
    if own is not None and own != run_folder and (own / RUN_INFO).is_file():
        return ResultsError(f"{text}; the same run is in {own}: remove one of the two folders")
    if own is not None and own != run_folder:
        return ResultsError(f"{text}; rename it to {own} or remove it")
    return ResultsError(f"{text}; remove it")
