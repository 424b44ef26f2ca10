"""Reading a results folder into tidy pandas tables.

A results folder (written by :mod:`neurocur.experiment`) looks like::

    DIR/config.toml
    DIR/summary.json
    DIR/runs/<condition>/run-<NNN>/episodes.parquet
    DIR/runs/<condition>/run-<NNN>/modules.parquet
    DIR/runs/<condition>/run-<NNN>/run.json

:func:`load` concatenates every run's tables into one episodes table and one
modules table, both led by the columns ``condition`` and ``run``.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

__all__ = ["load", "run_dirs"]

_RUN_FILES = ("episodes.parquet", "modules.parquet")


def run_dirs(results_dir: str | Path) -> list[Path]:
    """The run folders ``runs/<condition>/run-<NNN>`` of a results folder, sorted.

    Raises ValueError when ``results_dir`` is not a results folder (no ``runs/``
    folder, no run folder in it, or a run folder without its Parquet tables).
    """
    root = Path(results_dir)
    runs = root / "runs"
    if not root.is_dir():
        raise ValueError(f"results folder {root} does not exist or is not a directory")
    if not runs.is_dir():
        raise ValueError(
            f"{root} is not a results folder: expected a 'runs/' folder holding "
            "runs/<condition>/run-<NNN>/episodes.parquet (write one with the experiment runner)"
        )
    found = sorted(p for p in runs.glob("*/run-*") if p.is_dir())
    if not found:
        raise ValueError(
            f"{root} is not a results folder: 'runs/' holds no run folder "
            "runs/<condition>/run-<NNN>/"
        )
    for path in found:
        missing = [name for name in _RUN_FILES if not (path / name).is_file()]
        if missing:
            raise ValueError(f"run folder {path} lacks {', '.join(missing)}")
    return found


def _read(path: Path, condition: str, run: int) -> pd.DataFrame:
    table = pd.read_parquet(path)
    if "condition" not in table:
        table.insert(0, "condition", condition)
    if "run" not in table:
        table.insert(1, "run", run)
    return table


def load(results_dir: str | Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Load a results folder as ``(episodes, modules)`` DataFrames.

    Both tables hold every run of every condition, sorted by condition, run and
    episode (modules: by condition, run and module rank). ``condition`` and
    ``run`` are taken from the folder names when a table lacks them. The
    modules' ``gates`` column is normalised to a (possibly empty) string.
    """
    episodes, modules = [], []
    for path in run_dirs(results_dir):
        condition = path.parent.name
        try:
            run = int(path.name.removeprefix("run-"))
        except ValueError:
            raise ValueError(f"run folder {path} is not named run-<NNN>") from None
        episodes.append(_read(path / "episodes.parquet", condition, run))
        modules.append(_read(path / "modules.parquet", condition, run))
    episodes = pd.concat(episodes, ignore_index=True)
    modules = pd.concat([m for m in modules if len(m)] or modules[:1], ignore_index=True)
    if "gates" in modules:
        modules["gates"] = modules["gates"].fillna("").astype(str)
    episodes = episodes.sort_values(["condition", "run", "episode"], kind="stable")
    modules = modules.sort_values(["condition", "run", "module"], kind="stable")
    return episodes.reset_index(drop=True), modules.reset_index(drop=True)
