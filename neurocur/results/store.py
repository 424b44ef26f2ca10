"""The results store: the one owner of a results folder's layout, ``config.toml``, resume and loading.

Layout::

    OUT/config.toml                                the fully resolved experiment, its input files'
                                                   sha256 and the code that wrote its runs
    OUT/summary.json                               aggregate statistics over every finished run
    OUT/runs/<condition>/run-<NNN>/episodes.parquet
    OUT/runs/<condition>/run-<NNN>/modules.parquet
    OUT/runs/<condition>/run-<NNN>/run.json        the run's summary (order, seed, contexts, ...)
    OUT/runs/<condition>/run-<NNN>/<name>.parquet  further tables of the world type (iCub: features)
    OUT/runs/<condition>/run-<NNN>/agent/          the trained agent, when asked for (:mod:`.agents`)
    OUT/checkpoints/<condition>/run-<NNN>/         the last checkpoint of a run in progress (:mod:`.agents`)
    OUT/.lock                                      while a process writes (:mod:`.lock`)

**The folder is the truth** (:mod:`.reading`): a run's condition and number are those of its
path, and a run folder whose ``run.json`` or tables say otherwise is refused, as is a folder with
runs but no ``config.toml``. Nothing is written through a link the store did not make, nor
outside the folder (:mod:`.safeio`, :mod:`.names`).

**Writing.** A process writes only while it holds the folder's lock
(:meth:`ResultsStore.writing`). Every run is written into ``OUT/.partial/`` and moved into
place with one ``os.replace`` when it is complete, so a complete run folder is one with
its ``run.json``. When a run's folder already exists, a complete one is kept and an
incomplete one (its ``run.json`` deleted) is moved aside into ``.partial/`` and replaced.
``.partial/`` holds only debris, which the runner clears (:meth:`ResultsStore.clear_partial`)
before and after computing runs.

**Resume.** :meth:`ResultsStore.check` tells the ``config.toml`` a folder gets for an
experiment (refusing one that cannot resume there), and :meth:`ResultsStore.save_config` writes it.
Conditions new to a folder are added to it (a study can grow row by row), and
descriptions may be reworded; any other difference is refused, naming the first
differing key. An input file whose content changed is refused, and so is other code
unless explicitly accepted (:mod:`.fingerprint`); the folder then records every code
fingerprint that wrote runs into it.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import tomllib
from collections.abc import Iterable, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from neurocur.config import ConfigError

from .agents import AGENT, Checkpoints, discard, provenance, remove_empty, write_agent
from .configfile import CONFIG, comparable, folder_config, lookup
from .errors import ResultsError
from .fingerprint import changed_input, code_changed, code_fingerprint, file_hashes, portable
from .lock import FolderLock, locked
from .names import check_folder_name
from .reading import check_run_folder, join_runs, join_table, run_folders
from .runinfo import RUN_INFO, file_digests, read_run_info, run_number, run_path, scan_runs
from .safeio import atomic_text, own_dir
from .tomlio import difference_path, dotted, dumps_toml

__all__ = ["ResultsError", "ResultsStore", "RunResult", "load", "run_dirs"]

SUMMARY = "summary.json"
PARTIAL = ".partial"
#: the manifest a fit's output folder carries (:mod:`neurocur.fit.outdir`), which runs must not mix with
FIT_MANIFEST = "manifest.json"
CHECKPOINTS = "checkpoints"
_HEADER = """Resolved experiment written by neurocur; do not edit (resuming into this folder compares it).
Seeds: run i of every condition uses numpy SeedSequence(seeds.entropy, spawn_key=[i]);
each region's generator is that seed's child keyed by the region's name, the world's its child keyed by 'world'.
conditions.<name>.inputs: the sha256 of each input file; code: every code version that wrote runs into this folder."""


@dataclass(frozen=True)
class RunResult:
    """The tables and summary of one run (written as episodes.parquet, modules.parquet, run.json).

    Parameters
    ----------
    condition : str
        The run's condition.
    run : int
        The run's index.
    episodes : pandas.DataFrame
        The episodes table.
    modules : pandas.DataFrame
        The modules table.
    summary : dict
        The run's summary (run.json).
    tables : mapping of str to pandas.DataFrame
        Further per-run tables of the world type, written as ``<name>.parquet`` (iCub: ``features``).
    agent : tuple, optional
        The trained agent's state (:func:`~neurocur.results.agents.agent_state`), written as ``agent/``; None: not kept.
    """

    condition: str
    run: int
    episodes: pd.DataFrame
    modules: pd.DataFrame
    summary: dict
    #: further per-run tables of the world type, written as ``<name>.parquet`` (iCub: ``features``)
    tables: Mapping[str, pd.DataFrame] = field(default_factory=dict)
    #: the trained agent's state (:func:`~neurocur.results.agents.agent_state`), written as ``agent/``; None: not kept
    agent: tuple | None = None


class ResultsStore:
    """A results folder (it need not exist yet).

    Parameters
    ----------
    root : path
        The results folder.
    """

    def __init__(self, root):
        self.root = Path(root)

    def __repr__(self) -> str:
        return f"ResultsStore({str(self.root)!r})"

    # ------------------------------------------------------------------ layout

    def run_dir(self, condition: str, run: int) -> Path:
        """Folder of run ``run`` of ``condition`` (a ConfigError for a name that is no folder name:
        :func:`~neurocur.results.names.check_folder_name`)."""
        return run_path(self.root / "runs", condition, run)

    def completed(self, conditions: Iterable[str], runs: int) -> set[tuple[str, int]]:
        """The (condition, run) pairs already written (complete run folders).

        Every run folder of the results folder is checked against its ``run.json`` first
        (ResultsError on a copied or renamed folder); incomplete ones are left to be rewritten.
        """
        config = self.config()
        found = set()
        for path in self._scan():
            if (path / RUN_INFO).is_file():
                check_run_folder(path, config)
                found.add((path.parent.name, run_number(path.name)))
        wanted = set(conditions)
        return {(c, i) for c, i in found if c in wanted and i < runs}

    def checkpoints(self, condition: str, run: int, every: int, meta: Mapping, *, required: bool = False) -> Checkpoints:
        """The checkpoints of run ``run`` of ``condition`` (:class:`~neurocur.results.agents.Checkpoints`),
        in ``OUT/checkpoints/<condition>/run-<NNN>/``; removed when the run is written. ``meta`` gets the
        run's :func:`~neurocur.results.agents.provenance` (parameters as ``config.toml`` records them, code)."""
        final = self.run_dir(condition, run)
        return Checkpoints(own_dir(self.root, CHECKPOINTS, condition) / final.name, every,
                           {**meta, **provenance(self.config(), condition)}, required=required)

    def writing(self) -> AbstractContextManager[FolderLock]:
        """The folder's exclusive lock for a ``with`` block (see :mod:`neurocur.results.lock`):
        held by the process that writes runs into it; re-entrant within that process."""
        return locked(self.root)

    # ------------------------------------------------------------------ config.toml

    def config(self) -> dict | None:
        """The folder's resolved experiment (``config.toml``), or None when there is none yet."""
        return folder_config(self.root)

    def check(self, config: Mapping, *, inputs: Mapping[str, Iterable[str]] | None = None,
              accept_code_change: bool = False) -> dict | None:
        """The ``config.toml`` this folder gets for the experiment ``config`` (None: it stays as it is).

        ``inputs``: each condition's input file paths (a path that is not a file is left
        out); their sha256 are recorded as ``conditions.<name>.inputs``, and the running
        code's fingerprint in ``code``. Raises, writing nothing, when the experiment cannot
        resume here: ResultsError when an input file's content changed, or when the code
        changed and ``accept_code_change`` is false; ConfigError (naming the first
        differing key) for any other difference of a condition the folder already holds.
        """
        config = tomllib.loads(dumps_toml(config))
        for name, paths in (inputs or {}).items():
            hashes = file_hashes(paths)
            if hashes and name in config.get("conditions", {}):
                config["conditions"][name]["inputs"] = hashes
        config = portable(config)
        code = code_fingerprint()
        existing = self.config()
        if existing is None:
            if (self.root / FIT_MANIFEST).is_file():
                raise ResultsError(f"{self.root} is the output folder of a fit ({FIT_MANIFEST}), not a results "
                                   "folder; use another --out folder")
            if any(self._scan()):
                raise ResultsError(f"{self.root} holds runs but no {CONFIG}, so nothing tells which experiment "
                                   f"they belong to; restore its {CONFIG}, or use another --out folder")
            return {**config, "code": [code]}
        path = self.root / CONFIG
        for key in ("runs", "steps", "seeds", "code"):
            if key not in existing:
                raise ConfigError(path, key, "the key neurocur wrote there", "nothing (the key is missing); use "
                                  "another --out folder")
        existing = portable(existing)
        old_conditions, new_conditions = existing.get("conditions", {}), config.get("conditions", {})
        shared = [c for c in new_conditions if c in old_conditions]
        for name in shared:
            changed = changed_input(old_conditions[name].get("inputs", {}), new_conditions[name].get("inputs", {}))
            if changed:
                raise ResultsError(f"{self.root}: {changed}; use another --out folder")
        where = difference_path(comparable({**existing, "conditions": {c: old_conditions[c] for c in shared}}),
                                comparable({**config, "conditions": {c: new_conditions[c] for c in shared}}))
        if where is not None:
            raise ConfigError(path, dotted(where), f"{lookup(config, where)} (this experiment) to resume into "
                              f"this folder", f"{lookup(existing, where)}; use another --out folder or remove this one")
        recorded = existing.get("code", [])
        changed = code_changed(recorded, code)
        if changed and not accept_code_change:
            raise ResultsError(f"{self.root}: {changed}; resume anyway with --accept-code-change, "
                               "or use another --out folder")
        more_runs = config["runs"] > existing["runs"]  # a study grows by runs too: run i's seed does not depend on it
        grown = {**existing, "conditions": {**old_conditions, **new_conditions},
                 "code": [*recorded, code] if changed else recorded,
                 **({"runs": config["runs"], "seeds": config["seeds"]} if more_runs else {})}
        if "description" in config:
            grown["description"] = config["description"]
        return grown if grown != existing else None

    def save_config(self, config: Mapping | None) -> None:
        """Write ``config`` (what :meth:`check` returned) as the folder's ``config.toml``, creating
        the folder; None leaves it as it is. Call it while holding the folder's lock (:meth:`writing`)."""
        if config is not None:
            atomic_text(own_dir(self.root) / CONFIG, dumps_toml(config, header=_HEADER))

    # ------------------------------------------------------------------ runs

    def clear_partial(self) -> None:
        """Remove the debris of runs that were being written when a process stopped."""
        shutil.rmtree(self.root / PARTIAL, ignore_errors=True)  # never follows a link (removes nothing then)

    def write_run(self, result: RunResult) -> Path:
        """Write one run's tables and summary atomically into its run folder.

        When the run folder exists already (written meanwhile by another process, or left
        without its ``run.json``), a complete one is kept and this result dropped (a run is
        determined by its seed), and an incomplete one is replaced. ``run.json`` records the
        sha256 of each table (``tables``) and of the saved agent's files (``agent``). Nothing is written when the results folder no longer
        exists (moved or removed while it ran: it is never re-created behind the move), and
        no link on the way is followed (:mod:`.safeio`).
        """
        final = self.run_dir(result.condition, result.run)
        name = f"{result.condition}-{final.name}-{os.getpid()}"
        partial = own_dir(self.root, PARTIAL)
        tmp = partial / name
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir()
        result.episodes.to_parquet(tmp / "episodes.parquet", index=False)
        result.modules.to_parquet(tmp / "modules.parquet", index=False)
        for table_name, table in result.tables.items():
            check_folder_name(table_name, tmp, "tables")
            table.to_parquet(tmp / f"{table_name}.parquet", index=False)
        if result.agent is not None:
            write_agent(tmp / AGENT, result.agent, self.config(), result.condition)
        summary = {**result.summary, **file_digests(tmp)}
        (tmp / RUN_INFO).write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
        own_dir(self.root, "runs", result.condition)
        for _ in range(100):  # each pass moves an incomplete folder aside; another writer may race us
            try:
                os.replace(tmp, final)
                self._drop_checkpoint(result.condition, final.name)
                return final
            except OSError as exc:
                if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                    raise
            if final.is_symlink() or not final.is_dir():
                break
            if (final / RUN_INFO).is_file():
                shutil.rmtree(tmp, ignore_errors=True)
                return final
            aside = partial / f"incomplete-{name}"
            try:
                os.replace(final, aside)
            except FileNotFoundError:  # removed meanwhile: try again
                continue
            shutil.rmtree(aside, ignore_errors=True)
        shutil.rmtree(tmp, ignore_errors=True)
        raise ResultsError(f"{final}: cannot put the run in place (not a real folder, or replaced again and "
                           "again by another process); remove it")

    def _drop_checkpoint(self, condition: str, name: str) -> None:
        """Remove a written run's checkpoint (:func:`~neurocur.results.agents.discard`). Its condition's folder stays:
        another run of the condition may be in flight and not have saved into it yet (:meth:`tidy_checkpoints`)."""
        discard(self.root / CHECKPOINTS / condition / name)

    def tidy_checkpoints(self) -> None:
        """Remove the checkpoint folders left empty and the debris of killed saves (:func:`~.agents.remove_empty`); only while no
        run is in flight (the runner calls it once its executor has finished every run)."""
        remove_empty(self.root / CHECKPOINTS)

    def write_summary(self, summary: Mapping) -> Path:
        """Write ``summary.json`` (aggregate statistics, computed by :mod:`neurocur.analysis`)."""
        path = own_dir(self.root) / SUMMARY
        atomic_text(path, json.dumps(summary, indent=2, ensure_ascii=False) + "\n")
        return path

    # ------------------------------------------------------------------ reading

    def run_dirs(self) -> list[Path]:
        """The run folders ``runs/<condition>/run-<NNN>``, sorted, each checked against its path, its
        ``run.json`` and ``config.toml`` (:func:`~neurocur.results.reading.run_folders`: ValueError when the
        folder is not a results folder, ResultsError for a run folder that is not what its path says)."""
        return run_folders(self.root)

    def _scan(self) -> list[Path]:
        return scan_runs(self.root / "runs")

    def run_info(self, path: Path) -> dict:
        """The ``run.json`` of a run folder (:func:`~neurocur.results.runinfo.read_run_info`)."""
        return read_run_info(path)

    def load(self) -> tuple[pd.DataFrame, pd.DataFrame]:
        """``(episodes, modules)``: every run of every condition, led by ``condition`` and ``run``
        (:func:`~neurocur.results.reading.join_runs` of :meth:`run_dirs`).

        Sorted by condition, run and episode (modules: by condition, run and module rank);
        ``condition`` and ``run`` are taken from the folder names when a table lacks them,
        and must equal them when it has them (ResultsError otherwise).
        The modules' ``gates`` column is normalised to a (possibly empty) string.
        """
        return join_runs(self.run_dirs())

    def load_table(self, name: str, columns: Iterable[str] = ()) -> pd.DataFrame:
        """Every run's ``<name>.parquet`` as one table (empty, with ``columns``, when no run has one)."""
        return join_table(self.run_dirs(), name, columns)


def run_dirs(results_dir) -> list[Path]:
    """The run folders of a results folder (:meth:`ResultsStore.run_dirs`).

    Parameters
    ----------
    results_dir : path
        The results folder.

    Returns
    -------
    list of path
        The run folders.
    """
    return ResultsStore(results_dir).run_dirs()


def load(results_dir) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Load a results folder as ``(episodes, modules)`` DataFrames (:meth:`ResultsStore.load`).

    Parameters
    ----------
    results_dir : path
        The results folder.

    Returns
    -------
    (pandas.DataFrame, pandas.DataFrame)
        The episodes and modules tables of every run.
    """
    return ResultsStore(results_dir).load()
