"""The results store: the one owner of a results folder's layout, ``config.toml``, resume and loading.

Layout::

    OUT/config.toml                                the fully resolved experiment (version, seeds)
    OUT/summary.json                               aggregate statistics over every finished run
    OUT/runs/<condition>/run-<NNN>/episodes.parquet
    OUT/runs/<condition>/run-<NNN>/modules.parquet
    OUT/runs/<condition>/run-<NNN>/run.json        the run's summary (order, seed, contexts, ...)
    OUT/runs/<condition>/run-<NNN>/<name>.parquet  further tables of the world type (iCub: features)

Every run is written into ``OUT/.partial/`` and moved into place with one ``os.replace``
when it is complete, so a run folder exists only when all its files do.

Resume: :meth:`ResultsStore.open` writes ``config.toml`` into a new folder, or checks that
an existing folder holds the same experiment. Conditions new to a folder are added to it
(a study can grow row by row), and descriptions may be reworded; any other difference is
refused, naming the first differing key.
"""

from __future__ import annotations

import json
import os
import shutil
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from neurocur.config import ConfigError

from .tomlio import dumps_toml, first_difference

__all__ = ["ResultsStore", "RunResult", "load", "run_dirs"]

CONFIG = "config.toml"
SUMMARY = "summary.json"
PARTIAL = ".partial"
RUN_INFO = "run.json"
RUN_TABLES = ("episodes", "modules")
_HEADER = """Resolved experiment written by neurocur; do not edit (resuming into this folder compares it).
Seeds: run i of every condition uses numpy SeedSequence(seeds.entropy, spawn_key=seeds.spawn_keys[i]);
each region's generator is that seed's child keyed by the region's name (the sensory region's seeds the world)."""


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
        """The (condition, run) pairs already written."""
        return {(c, i) for c in conditions for i in range(runs) if (self.run_dir(c, i) / RUN_INFO).is_file()}

    # ------------------------------------------------------------------ config.toml

    def config(self) -> dict | None:
        """The folder's resolved experiment (``config.toml``), or None when there is none yet."""
        path = self.root / CONFIG
        if not path.is_file():
            return None
        with path.open("rb") as fh:
            return tomllib.load(fh)

    def open(self, config: Mapping) -> None:
        """Create the folder with ``config`` as its ``config.toml``, or check that it holds the
        same experiment (resume). Conditions new to the folder are added to its config."""
        config = tomllib.loads(dumps_toml(config))
        existing = self.config()
        path = self.root / CONFIG
        if existing is None:
            self.root.mkdir(parents=True, exist_ok=True)
            _atomic_text(path, dumps_toml(config, header=_HEADER))
            return
        old_conditions, new_conditions = existing.get("conditions", {}), config.get("conditions", {})
        shared = [c for c in new_conditions if c in old_conditions]
        key = first_difference(_without_descriptions({**existing, "conditions": {c: old_conditions[c] for c in shared}}),
                               _without_descriptions({**config, "conditions": {c: new_conditions[c] for c in shared}}))
        if key is not None:
            raise ConfigError(path, key, f"{_lookup(config, key)!r} (this experiment) to resume into this folder",
                              f"{_lookup(existing, key)!r}; use another --out folder or remove this one")
        grown = {**existing, "conditions": {**old_conditions, **new_conditions}}
        if "description" in config:
            grown["description"] = config["description"]
        if grown != existing:
            _atomic_text(path, dumps_toml(grown, header=_HEADER))

    # ------------------------------------------------------------------ runs

    def clear_partial(self) -> None:
        """Remove the debris of runs that were being written when a process stopped."""
        shutil.rmtree(self.root / PARTIAL, ignore_errors=True)

    def write_run(self, result: RunResult) -> Path:
        """Write one run's tables and summary atomically into its run folder."""
        final = self.run_dir(result.condition, result.run)
        tmp = self.root / PARTIAL / f"{result.condition}-run-{result.run:03d}-{os.getpid()}"
        if tmp.exists():
            shutil.rmtree(tmp)
        tmp.mkdir(parents=True)
        result.episodes.to_parquet(tmp / "episodes.parquet", index=False)
        result.modules.to_parquet(tmp / "modules.parquet", index=False)
        for name, table in result.tables.items():
            table.to_parquet(tmp / f"{name}.parquet", index=False)
        (tmp / RUN_INFO).write_text(json.dumps(result.summary, indent=2) + "\n", encoding="utf-8")
        final.parent.mkdir(parents=True, exist_ok=True)
        os.replace(tmp, final)
        return final

    def write_summary(self, summary: Mapping) -> Path:
        """Write ``summary.json`` (aggregate statistics, computed by :mod:`neurocur.analysis`)."""
        path = self.root / SUMMARY
        _atomic_text(path, json.dumps(summary, indent=2, ensure_ascii=False) + "\n")
        return path

    # ------------------------------------------------------------------ reading

    def run_dirs(self) -> list[Path]:
        """The run folders ``runs/<condition>/run-<NNN>``, sorted.

        Raises ValueError when the folder is not a results folder (no ``runs/`` folder, no
        run folder in it, or a run folder without its Parquet tables).
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
        return found

    def run_info(self, path: Path) -> dict:
        """The ``run.json`` of a run folder."""
        return json.loads((Path(path) / RUN_INFO).read_text(encoding="utf-8"))

    def load(self) -> tuple[pd.DataFrame, pd.DataFrame]:
        """``(episodes, modules)``: every run of every condition, led by ``condition`` and ``run``.

        Sorted by condition, run and episode (modules: by condition, run and module rank);
        ``condition`` and ``run`` are taken from the folder names when a table lacks them.
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
        tables = [pd.read_parquet(p / f"{name}.parquet") for p in self.run_dirs() if (p / f"{name}.parquet").is_file()]
        tables = [t for t in tables if len(t)]
        if not tables:
            return pd.DataFrame(columns=list(columns))
        return pd.concat(tables, ignore_index=True)

    @staticmethod
    def _read(run_folder: Path, name: str) -> pd.DataFrame:
        table = pd.read_parquet(run_folder / f"{name}.parquet")
        try:
            run = int(run_folder.name.removeprefix("run-"))
        except ValueError:
            raise ValueError(f"run folder {run_folder} is not named run-<NNN>") from None
        if "condition" not in table:
            table.insert(0, "condition", run_folder.parent.name)
        if "run" not in table:
            table.insert(1, "run", run)
        return table


def run_dirs(results_dir) -> list[Path]:
    """The run folders of a results folder (:meth:`ResultsStore.run_dirs`)."""
    return ResultsStore(results_dir).run_dirs()


def load(results_dir) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Load a results folder as ``(episodes, modules)`` DataFrames (:meth:`ResultsStore.load`)."""
    return ResultsStore(results_dir).load()


def _without_descriptions(tree):
    """``tree`` without its ``description`` entries: prose, which does not change a result."""
    if isinstance(tree, dict):
        return {k: _without_descriptions(v) for k, v in tree.items() if k != "description"}
    return tree


def _lookup(tree, dotted: str):
    node = tree
    for part in dotted.replace("[", ".[").split("."):
        if not part:
            continue
        try:
            node = node[int(part[1:-1])] if part.startswith("[") else node[part]
        except (KeyError, IndexError, TypeError):
            return "(missing)"
    return node if not isinstance(node, (dict, list)) else "(a table)" if isinstance(node, dict) else node


def _atomic_text(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
