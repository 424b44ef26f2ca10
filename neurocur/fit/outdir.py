"""The output folder of a fit command (``fit``, ``recover``, ``compare``, ``sbi``): checked, locked, replaced whole.

- **Where.** ``--out`` is a real folder (not a symbolic link, not a file), neither a results
  folder nor inside one (a folder holding the store's ``config.toml`` or run folders ``runs/<condition>/run-<NNN>``,
  :mod:`neurocur.results.store`: ``neurocur run`` would resume into it), nor the input data folder or
  inside it; the input is not inside ``--out`` either (:func:`check_out`).
- **One writer.** The folder is locked while the command runs (:func:`neurocur.results.lock.locked`):
  a second command into it is refused, naming the holder.
- **Replaced whole.** ``OUT/manifest.json`` records the command, its arguments, every file it wrote
  with its sha256, and ``complete`` (false until the command has written everything, so a
  killed or interrupted command is marked). A new command removes the files the previous
  manifest lists, and nothing else; a folder holding anything no manifest lists (other than
  the folders a command keeps, ``sbi``'s training runs) is refused unless it is empty.
- **Spreadsheet-safe.** Every CSV is written through :func:`spreadsheet_safe`: a text cell that
  begins with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return (and is not a plain number)
  gets a leading single quote, so a spreadsheet shows it instead of running it (OWASP, "CSV
  Injection"); numbers stay numbers.

Files are written whole (:func:`neurocur.results.safeio.atomic_bytes`), never through a link.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import stat
import sys
import tomllib
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from ..results.lock import LOCK, locked
from ..results.safeio import atomic_bytes, atomic_text
from ..results.store import CONFIG as _RESULTS_CONFIG
from ..results.store import FIT_MANIFEST

__all__ = ["MANIFEST", "FitInterrupted", "FitOutput", "check_out", "fit_output", "spreadsheet_safe"]

MANIFEST = FIT_MANIFEST  # the name the results store looks for to refuse runs into a fit's folder
#: with the store's config.toml, what makes a folder a results folder (neurocur.results.store's layout)
_RESULTS_RUNS = "runs"
_FORMULA = ("=", "+", "-", "@", "\t", "\r")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


class FitInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a fit command; ``str(exc)`` says what it left."""


def spreadsheet_safe(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with every text cell, column name and index label that a spreadsheet would run as a formula
    prefixed with a single quote; numbers (and text that is a plain number, such as ``-3``) unchanged.

    Parameters
    ----------
    table : pandas.DataFrame
        The table to write.

    Returns
    -------
    pandas.DataFrame
        A copy, made safe.
    """
    def cell(value):
        if isinstance(value, str) and value.startswith(_FORMULA) and not _NUMBER.fullmatch(value):
            return "'" + value
        return value

    out = table.copy()
    for column in out.columns:
        if not pd.api.types.is_numeric_dtype(out[column].dtype):
            out[column] = out[column].map(cell)
    out.columns = out.columns.map(cell)
    out.index = out.index.map(cell)
    return out


def _results_folder(path: Path) -> str | None:
    """What makes ``path`` a results folder (the store's ``config.toml``, with its ``runs``, ``seeds`` and
    ``conditions``, or a run folder), or None; another program's ``config.toml`` does not."""
    config = path / _RESULTS_CONFIG
    if config.is_file() and not config.is_symlink():
        try:
            keys = tomllib.loads(config.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
            keys = {}
        if {"runs", "seeds", "conditions"} <= set(keys):
            return _RESULTS_CONFIG
    runs = path / _RESULTS_RUNS
    if runs.is_dir() and not runs.is_symlink() and any(runs.glob("*/run-*")):
        return f"{_RESULTS_RUNS}/<condition>/run-<NNN>"
    return None


def check_out(out: Path, inputs: Sequence[Path] = ()) -> None:
    """ValueError unless ``out`` may be a fit command's output folder (module docstring); writes nothing.

    Parameters
    ----------
    out : path
        The ``--out`` folder.
    inputs : sequence of path
        The input data, which ``out`` must neither hold nor lie in.
    """
    out = Path(out)
    if out.is_symlink():
        raise ValueError(f"--out: expected a folder, not a symbolic link, got {str(out)!r}")
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out: expected a folder, got {str(out)!r} (a file)")
    real = out.resolve()
    for folder in (real, *real.parents):
        marker = _results_folder(folder)
        if marker is not None:
            where = "is" if folder == real else f"lies inside {str(folder)!r}, which is"
            raise ValueError(f"--out: expected a folder outside any results folder, got {str(out)!r}, which {where} a "
                             f"results folder (it holds {marker}; 'neurocur run' would resume into it)")
    for given in inputs:
        data = Path(given).resolve()
        if data == real or real in data.parents or data in real.parents:
            raise ValueError(f"--out: expected a folder apart from the input {str(given)!r}, got {str(out)!r}")


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


class FitOutput:
    """An open output folder (:func:`fit_output`): write files into it; each is recorded in the manifest.

    Parameters
    ----------
    root : path
        The folder.
    command : str
        The command writing it, recorded in the manifest.
    arguments : dict
        The command's arguments, recorded in the manifest.
    folders : sequence of str
        Sub-folders this command keeps from one run to the next.
    """

    def __init__(self, root: Path, command: str, arguments: dict, folders: Sequence[str]):
        self.root = root
        self.manifest = {"command": command, "arguments": arguments, "complete": False, "files": {},
                         "folders": list(folders), "warnings": []}

    def write_bytes(self, name: str, data: bytes) -> Path:
        """Write ``OUT/name`` whole and record it."""
        self.manifest["files"][name] = _digest(data)
        self._save()  # listed before it exists: a killed command's next run removes it
        atomic_bytes(self.root / name, data)
        return self.root / name

    def write_text(self, name: str, text: str) -> Path:
        return self.write_bytes(name, text.encode("utf-8"))

    def write_csv(self, name: str, table: pd.DataFrame, *, index: bool = False) -> Path:
        """``table`` as CSV, spreadsheet-safe (:func:`spreadsheet_safe`)."""
        return self.write_text(name, spreadsheet_safe(table).to_csv(index=index))

    def write_figure(self, name: str, fig) -> Path:
        from ..analysis.figures.style import save_figure

        save_figure(fig, self.root / name)
        self.manifest["files"][name] = _digest((self.root / name).read_bytes())
        self._save()
        return self.root / name

    def remove(self, name: str) -> None:
        """Remove a file this command wrote (a partial table, once the whole one is written)."""
        if self.manifest["files"].pop(name, None) is not None:
            _unlink(self.root / name)
            self._save()

    def warn(self, text: str) -> None:
        """Record a warning in the manifest and print it (one line on stderr)."""
        self.manifest["warnings"].append(text)
        print(f"neurocur {self.manifest['command']}: warning: {text}", file=sys.stderr, flush=True)
        self._save()

    def _save(self) -> None:
        atomic_text(self.root / MANIFEST, json.dumps(self.manifest, indent=2, default=str) + "\n")


def _unlink(path: Path) -> None:
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if stat.S_ISDIR(mode):
        raise ValueError(f"{path}: expected a file a previous fit wrote (its manifest lists it), got a folder; "
                         "remove it or use another --out folder")
    os.unlink(path)  # a link is removed, never followed


def _previous(root: Path, folders: Sequence[str]) -> dict:
    """The previous command's manifest in ``root`` ({} for an empty or new folder), checked: everything in the
    folder is listed there, and the folders it kept are ones this command keeps too."""
    entries = sorted(set(os.listdir(root)) - {MANIFEST, LOCK}) if root.is_dir() else []
    path = root / MANIFEST
    manifest = {}
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise ValueError(f"{path}: expected the manifest a fit command wrote, got a link or not a file; remove it")
    if path.is_file():
        try:
            manifest = json.loads(path.read_text(encoding="utf-8"))
        except (ValueError, UnicodeDecodeError) as exc:
            raise ValueError(f"{path}: expected the manifest a fit command wrote (JSON), got {exc}; use another "
                             "--out folder") from None
        if not (isinstance(manifest, dict) and isinstance(manifest.get("files"), dict)
                and isinstance(manifest.get("folders", []), list)):
            raise ValueError(f"{path}: expected the manifest a fit command wrote (files, folders), got something "
                             "else; use another --out folder")
    listed = set(manifest.get("files", {})) | set(manifest.get("folders", []))
    stray = [e for e in entries if e not in listed]
    if stray:
        raise ValueError(f"--out {root}: expected an empty folder or one a fit command wrote, got {stray[0]!r}, "
                         f"which no {MANIFEST} of a fit lists; use another --out folder or remove it")
    foreign = [f for f in manifest.get("folders", []) if f in entries and f not in folders]
    if foreign:
        raise ValueError(f"--out {root}: holds {foreign[0]!r}, which 'neurocur {manifest.get('command')}' keeps there "
                         "and this command would not replace; use another --out folder or remove it")
    return manifest


@contextmanager
def fit_output(out, command: str, arguments: dict, *, inputs: Sequence[Path] = (),
               folders: Sequence[str] = ()) -> Iterator[FitOutput]:
    """The output folder ``out`` for the ``with`` block: checked (:func:`check_out`), locked, the previous
    command's files removed, and a manifest written at once (``complete: false``) and at the end
    (``complete: true``). Ctrl-C inside the block becomes :class:`FitInterrupted`, saying what the folder holds.

    Parameters
    ----------
    out : path
        The ``--out`` folder.
    command : str
        The command, recorded in the manifest.
    arguments : dict
        The command's arguments, recorded in the manifest.
    inputs : sequence of path
        The input data (:func:`check_out`).
    folders : sequence of str
        Sub-folders this command keeps from one run to the next.

    Yields
    ------
    FitOutput
        The open folder.
    """
    root = Path(out)
    check_out(root, inputs)
    with locked(root):
        previous = _previous(root, folders)
        output = FitOutput(root, command, arguments, folders)
        for name in previous.get("files", {}):
            _unlink(root / name)
        output._save()
        try:
            yield output
        except FitInterrupted:
            raise
        except KeyboardInterrupt:
            written = sorted(output.manifest["files"])
            kept = f"{', '.join(written)} written so far" if written else "no result written"
            raise FitInterrupted(f"{kept} in {root}; its {MANIFEST} says complete: false") from None
        output.manifest["complete"] = True
        output._save()
