"""The results store: the one owner of a results folder's layout, ``config.toml``, resume and loading.

Layout::

    OUT/config.toml                                the fully resolved experiment, its input files'
                                                   sha256 and the code that wrote its runs
    OUT/summary.json                               aggregate statistics over every finished run
    OUT/runs/<condition>/run-<NNN>/episodes.parquet
    OUT/runs/<condition>/run-<NNN>/modules.parquet
    OUT/runs/<condition>/run-<NNN>/run.json        the run's summary (order, seed, contexts, ...)
    OUT/runs/<condition>/run-<NNN>/<name>.parquet  further tables of the world type (iCub: features)
    OUT/.lock                                      while a process writes (:mod:`.lock`)

**The folder is the truth.** A run's condition and number are those of its path; the
``condition`` and ``run`` of its ``run.json`` and of its tables must agree, else reading
(and resuming) fails naming the folder, what its files say and, when the same run also
exists under its own name, both paths (a copied or renamed folder).

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

from .fingerprint import changed_input, code_changed, code_fingerprint, file_hashes
from .lock import FolderLock, locked
from .tomlio import difference_path, dotted, dumps_toml

__all__ = ["ResultsError", "ResultsStore", "RunResult", "load", "run_dirs"]

CONFIG = "config.toml"
SUMMARY = "summary.json"
PARTIAL = ".partial"
RUN_INFO = "run.json"
RUN_TABLES = ("episodes", "modules")
_HEADER = """Resolved experiment written by neurocur; do not edit (resuming into this folder compares it).
Seeds: run i of every condition uses numpy SeedSequence(seeds.entropy, spawn_key=seeds.spawn_keys[i]);
each region's generator is that seed's child keyed by the region's name (the sensory region's seeds the world).
conditions.<name>.inputs: the sha256 of each input file; code: every code version that wrote runs into this folder."""
#: top-level keys compared on resume by their own rules (the code fingerprint), not as configuration;
#: ``control`` names the condition the analysis compares against and changes no run, so a folder
#: written before experiment files named it resumes
_NOT_COMPARED = ("code", "neurocur_version", "runs", "control")


class ResultsError(ValueError):
    """A results folder that cannot be read or resumed as it is (the message says why and what to do)."""


@dataclass(frozen=True)
class RunResult:
    """The tables and summary of one run (written as episodes.parquet, modules.parquet, run.json)."""

    condition: str
    run: int
    episodes: pd.DataFrame
    modules: pd.DataFrame
    summary: dict
    #: further per-run tables of the world type, written as ``<name>.parquet`` (iCub: ``features``)
    tables: Mapping[str, pd.DataFrame] = field(default_factory=dict)


class ResultsStore:
    """A results folder (it need not exist yet)."""

    def __init__(self, root):
        self.root = Path(root)

    def __repr__(self) -> str:
        return f"ResultsStore({str(self.root)!r})"

    # ------------------------------------------------------------------ layout

    def run_dir(self, condition: str, run: int) -> Path:
        """Folder of run ``run`` of ``condition``."""
        return self.root / "runs" / condition / f"run-{run:03d}"

    def completed(self, conditions: Iterable[str], runs: int) -> set[tuple[str, int]]:
        """The (condition, run) pairs already written (complete run folders).

        Every run folder of the results folder is checked against its ``run.json`` first
        (ResultsError on a copied or renamed folder); incomplete ones are left to be rewritten.
        """
        for path in sorted((self.root / "runs").glob("*/run-*")):
            if path.is_dir() and (path / RUN_INFO).is_file():
                self._check_info(path)
        return {(c, i) for c in conditions for i in range(runs) if (self.run_dir(c, i) / RUN_INFO).is_file()}

    def writing(self) -> AbstractContextManager[FolderLock]:
        """The folder's exclusive lock for a ``with`` block (see :mod:`neurocur.results.lock`):
        held by the process that writes runs into it; re-entrant within that process."""
        return locked(self.root)

    # ------------------------------------------------------------------ config.toml

    def config(self) -> dict | None:
        """The folder's resolved experiment (``config.toml``), or None when there is none yet."""
        path = self.root / CONFIG
        if not path.is_file():
            return None
        with path.open("rb") as fh:
            return tomllib.load(fh)

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
        code = code_fingerprint()
        existing = self.config()
        if existing is None:
            return {**config, "code": [code]}
        path = self.root / CONFIG
        old_conditions, new_conditions = existing.get("conditions", {}), config.get("conditions", {})
        shared = [c for c in new_conditions if c in old_conditions]
        for name in shared:
            changed = changed_input(old_conditions[name].get("inputs", {}), new_conditions[name].get("inputs", {}))
            if changed:
                raise ResultsError(f"{self.root}: {changed}; use another --out folder")
        where = difference_path(_comparable({**existing, "conditions": {c: old_conditions[c] for c in shared}}),
                                _comparable({**config, "conditions": {c: new_conditions[c] for c in shared}}))
        if where is not None:
            raise ConfigError(path, dotted(where), f"{_lookup(config, where)} (this experiment) to resume into "
                              f"this folder", f"{_lookup(existing, where)}; use another --out folder or remove this one")
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
            self.root.mkdir(parents=True, exist_ok=True)
            _atomic_text(self.root / CONFIG, dumps_toml(config, header=_HEADER))

    # ------------------------------------------------------------------ runs

    def clear_partial(self) -> None:
        """Remove the debris of runs that were being written when a process stopped."""
        shutil.rmtree(self.root / PARTIAL, ignore_errors=True)

    def write_run(self, result: RunResult) -> Path:
        """Write one run's tables and summary atomically into its run folder.

        When the run folder exists already (written meanwhile by another process, or left
        without its ``run.json``), a complete one is kept and this result dropped (a run is
        determined by its seed), and an incomplete one is replaced.
        """
        final = self.run_dir(result.condition, result.run)
        name = f"{result.condition}-run-{result.run:03d}-{os.getpid()}"
        tmp = self.root / PARTIAL / name
        if tmp.exists():
            shutil.rmtree(tmp)
        tmp.mkdir(parents=True)
        result.episodes.to_parquet(tmp / "episodes.parquet", index=False)
        result.modules.to_parquet(tmp / "modules.parquet", index=False)
        for table_name, table in result.tables.items():
            table.to_parquet(tmp / f"{table_name}.parquet", index=False)
        (tmp / RUN_INFO).write_text(json.dumps(result.summary, indent=2) + "\n", encoding="utf-8")
        final.parent.mkdir(parents=True, exist_ok=True)
        while True:
            try:
                os.replace(tmp, final)
                return final
            except OSError as exc:
                if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                    raise
            if (final / RUN_INFO).is_file():
                shutil.rmtree(tmp, ignore_errors=True)
                return final
            aside = self.root / PARTIAL / f"incomplete-{name}"
            try:
                os.replace(final, aside)
            except FileNotFoundError:  # removed meanwhile: try again
                continue
            shutil.rmtree(aside, ignore_errors=True)

    def write_summary(self, summary: Mapping) -> Path:
        """Write ``summary.json`` (aggregate statistics, computed by :mod:`neurocur.analysis`)."""
        path = self.root / SUMMARY
        _atomic_text(path, json.dumps(summary, indent=2, ensure_ascii=False) + "\n")
        return path

    # ------------------------------------------------------------------ reading

    def run_dirs(self) -> list[Path]:
        """The run folders ``runs/<condition>/run-<NNN>``, sorted.

        Raises ValueError when the folder is not a results folder (no ``runs/`` folder, no
        run folder in it, or a run folder without its Parquet tables), and ResultsError for
        a run folder without its ``run.json`` or whose ``run.json`` names another
        condition or run than its path.
        """
        root, runs = self.root, self.root / "runs"
        if not root.is_dir():
            raise ValueError(f"results folder {root} does not exist or is not a directory")
        if not runs.is_dir():
            raise ValueError(f"{root} is not a results folder: expected a 'runs/' folder holding "
                             "runs/<condition>/run-<NNN>/episodes.parquet (write one with 'neurocur run')")
        found = sorted(p for p in runs.glob("*/run-*") if p.is_dir())
        if not found:
            raise ValueError(f"{root} is not a results folder: 'runs/' holds no run folder runs/<condition>/run-<NNN>/")
        for path in found:
            missing = [f"{name}.parquet" for name in RUN_TABLES if not (path / f"{name}.parquet").is_file()]
            if missing:
                raise ValueError(f"run folder {path} lacks {', '.join(missing)}")
            if not (path / RUN_INFO).is_file():
                raise ResultsError(f"run folder {path} is incomplete: it lacks {RUN_INFO} "
                                   "('neurocur run' into this folder computes it again)")
            self._check_info(path)
        return found

    def run_info(self, path: Path) -> dict:
        """The ``run.json`` of a run folder."""
        try:
            info = json.loads((Path(path) / RUN_INFO).read_text(encoding="utf-8"))
        except ValueError as exc:
            raise ResultsError(f"{Path(path) / RUN_INFO}: expected a run summary (JSON), got {exc}") from None
        if not isinstance(info, dict):
            raise ResultsError(f"{Path(path) / RUN_INFO}: expected a run summary (a JSON object)")
        return info

    def load(self) -> tuple[pd.DataFrame, pd.DataFrame]:
        """``(episodes, modules)``: every run of every condition, led by ``condition`` and ``run``.

        Sorted by condition, run and episode (modules: by condition, run and module rank);
        ``condition`` and ``run`` are taken from the folder names when a table lacks them,
        and must equal them when it has them (ResultsError otherwise).
        The modules' ``gates`` column is normalised to a (possibly empty) string.
        """
        dirs = self.run_dirs()
        episodes = pd.concat([self._read(p, "episodes") for p in dirs], ignore_index=True)
        modules = [self._read(p, "modules") for p in dirs]
        modules = pd.concat([m for m in modules if len(m)] or modules[:1], ignore_index=True)
        if "gates" in modules:
            modules["gates"] = modules["gates"].fillna("").astype(str)
        episodes = episodes.sort_values(["condition", "run", "episode"], kind="stable")
        modules = modules.sort_values(["condition", "run", "module"], kind="stable")
        return episodes.reset_index(drop=True), modules.reset_index(drop=True)

    def load_table(self, name: str, columns: Iterable[str] = ()) -> pd.DataFrame:
        """Every run's ``<name>.parquet`` as one table (empty, with ``columns``, when no run has one)."""
        tables = [self._read(p, name) for p in self.run_dirs() if (p / f"{name}.parquet").is_file()]
        tables = [t for t in tables if len(t)]
        if not tables:
            return pd.DataFrame(columns=list(columns))
        return pd.concat(tables, ignore_index=True)

    def _read(self, run_folder: Path, name: str) -> pd.DataFrame:
        """A run's table, its ``condition`` and ``run`` checked against (or taken from) the folder."""
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
            raise self._mismatch(run_folder, f"{name}.parquet", said.get("condition", condition), said.get("run", run))
        return table

    def _check_info(self, run_folder: Path) -> None:
        """ResultsError when the ``run.json`` of ``run_folder`` names another condition or run than its path."""
        info = self.run_info(run_folder)
        condition, run = run_folder.parent.name, _run_number(run_folder)
        said = (info.get("condition", condition), info.get("run", run))
        if said != (condition, run):
            raise self._mismatch(run_folder, RUN_INFO, *said)

    def _mismatch(self, run_folder: Path, file: str, condition, run) -> ResultsError:
        text = (f"run folder {run_folder} holds run {run} of condition {condition!r} by its {file}, not run "
                f"{_run_number(run_folder)} of {run_folder.parent.name!r} as its path says (a copied or renamed folder?)")
        own = self.run_dir(str(condition), run) if isinstance(run, int) else None
        if own is not None and own != run_folder and (own / RUN_INFO).is_file():
            return ResultsError(f"{text}; the same run is in {own}: remove one of the two folders")
        if own is not None and own != run_folder:
            return ResultsError(f"{text}; rename it to {own} or remove it")
        return ResultsError(f"{text}; remove it")


def run_dirs(results_dir) -> list[Path]:
    """The run folders of a results folder (:meth:`ResultsStore.run_dirs`)."""
    return ResultsStore(results_dir).run_dirs()


def load(results_dir) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Load a results folder as ``(episodes, modules)`` DataFrames (:meth:`ResultsStore.load`)."""
    return ResultsStore(results_dir).load()


def _run_number(run_folder: Path) -> int:
    try:
        return int(run_folder.name.removeprefix("run-"))
    except ValueError:
        raise ValueError(f"run folder {run_folder} is not named run-<NNN>") from None


def _comparable(config: Mapping) -> dict:
    """``config`` as compared on resume: without the keys of :data:`_NOT_COMPARED`, descriptions, and
    the number of runs (a folder grows by runs; each run's seed depends only on its index)."""
    kept = {k: v for k, v in config.items() if k not in _NOT_COMPARED}
    if isinstance(kept.get("seeds"), Mapping):
        kept["seeds"] = {k: v for k, v in kept["seeds"].items() if k != "spawn_keys"}
    return _without_descriptions(kept)


def _without_descriptions(tree):
    """``tree`` without its ``description`` entries: prose, which does not change a result."""
    if isinstance(tree, dict):
        return {k: _without_descriptions(v) for k, v in tree.items() if k != "description"}
    return tree


def _lookup(tree, path: tuple) -> str:
    """The value at ``path`` (from :func:`difference_path`) as text: its repr, ``"a table"``, or
    ``"nothing (not set)"`` when the tree has no such key."""
    node = tree
    for part in path:
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            return "nothing (not set)"
    return "a table" if isinstance(node, dict) else repr(node)


def _atomic_text(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
