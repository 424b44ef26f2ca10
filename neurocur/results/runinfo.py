"""What a run folder must be to count: its spelling, its ``run.json`` and the digest of its tables.

A run folder is ``runs/<condition>/run-<NNN>``, spelled exactly as :func:`run_folder_name`
spells its number (``run-001``, never ``run-1`` or ``run-0_01``) and a real directory (not a
link). Its ``run.json`` names its condition and run (an integer), and, as written by
:meth:`~neurocur.results.ResultsStore.write_run`, its seed, its steps and the sha256 of each
of its tables (``tables``) and of its saved agent's files (``agent``, when it kept one).
:func:`check_run_info` compares them with the folder's path and ``config.toml``: a run computed
for another experiment (other steps, another seed) or whose tables or agent were changed
afterwards (or its agent removed or made a link) is refused, naming the folder and the key; an
agent that ``run.json`` does not record is never loaded (:func:`neurocur.load_agent`).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from collections.abc import Mapping
from pathlib import Path

from .agents import AGENT
from .errors import ResultsError
from .names import check_folder_name
from .safeio import UnsafePath, open_real_dir, read_own

__all__ = ["RUN_INFO", "agent_digests", "check_run_info", "digests", "file_digests", "read_run_info", "run_folder_name",
           "run_number", "run_path", "run_spawn_key", "scan_runs", "seed_json", "seeds_record"]

_RUN = re.compile(r"run-(\d{3,})")
#: the run's summary file in its folder
RUN_INFO = "run.json"


def read_run_info(folder) -> dict:
    """The ``run.json`` of a run folder (a JSON object; ResultsError otherwise).

    Parameters
    ----------
    folder : path
        The run folder.

    Returns
    -------
    dict
        Its ``run.json``.
    """
    path = Path(folder) / RUN_INFO
    try:
        info = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise ResultsError(f"{path}: expected a run summary (JSON), got {exc}") from None
    if not isinstance(info, dict):
        raise ResultsError(f"{path}: expected a run summary (a JSON object)")
    return info


#: how ``config.toml`` records the spawn key of run i (the same for every run count: nothing per run)
SPAWN_KEY_RULE = "[run]"


def seeds_record(entropy: int) -> dict:
    """The ``seeds`` table of ``config.toml``: run i of every condition uses
    ``SeedSequence(entropy, spawn_key=(i,))``; written in constant size, however many runs.

    Parameters
    ----------
    entropy : int
        The experiment's seed (``SeedSequence.entropy``).

    Returns
    -------
    dict
        ``{"entropy": entropy, "spawn_key": "[run]"}``.
    """
    return {"entropy": entropy, "spawn_key": SPAWN_KEY_RULE}


def seed_json(seed) -> dict:
    """A run's ``SeedSequence`` as its ``run.json`` (and a checkpoint or saved agent) records it.

    Parameters
    ----------
    seed : numpy.random.SeedSequence
        The run's seed.

    Returns
    -------
    dict
        ``{"entropy": ..., "spawn_key": [...]}``.
    """
    return {"entropy": seed.entropy, "spawn_key": list(seed.spawn_key)}


def run_spawn_key(seeds: Mapping, run: int) -> list:
    """The spawn key of run ``run`` as a ``seeds`` table records it (a folder written before the rule
    lists every run's key as ``spawn_keys``).

    Parameters
    ----------
    seeds : mapping
        The ``seeds`` table of a folder's ``config.toml``.
    run : int
        The run's index.

    Returns
    -------
    list
        ``[run]``, or the key listed for the run in ``spawn_keys``.
    """
    keys = seeds.get("spawn_keys")
    return list(keys[run]) if isinstance(keys, list) and run < len(keys) else [run]


def run_folder_name(run: int) -> str:
    """``run-007``: the one spelling of run 7's folder.

    Parameters
    ----------
    run : int
        The run's index (zero-padded to three digits; more digits above 999).

    Returns
    -------
    str
        The folder's name.
    """
    return f"run-{run:03d}"


def run_number(name: str) -> int | None:
    """The run number of a canonically spelled run folder name, else None.

    Parameters
    ----------
    name : str
        A folder's name.

    Returns
    -------
    int or None
        The run's index when ``name`` is exactly [`run_folder_name`][neurocur.results.runinfo.run_folder_name] of it.
    """
    match = _RUN.fullmatch(name)
    if match is None or run_folder_name(int(match.group(1))) != name:
        return None
    return int(match.group(1))


def run_path(runs: Path, condition: str, run: int) -> Path:
    """``runs/<condition>/run-<NNN>``: where run ``run`` of ``condition`` lives.

    Parameters
    ----------
    runs : path
        The ``runs/`` folder of a results folder.
    condition : str
        The condition's name.
    run : int
        The run's index.

    Returns
    -------
    path
        The run's folder.

    Raises
    ------
    ConfigError
        When ``condition`` is no folder name ([`check_folder_name`][neurocur.results.names.check_folder_name]).
    """
    check_folder_name(condition, runs, "condition")
    return runs / condition / run_folder_name(run)


def scan_runs(runs: Path) -> list[Path]:
    """Every run folder ``runs/<condition>/run-<NNN>``, sorted; ResultsError for an entry of
    ``runs/`` or of a condition folder that is a link, or a ``run-*`` entry spelled otherwise.

    Parameters
    ----------
    runs : path
        The ``runs/`` folder of a results folder (no such folder: an empty list).

    Returns
    -------
    list of path
        The run folders, by condition then run name; entries of a condition folder not starting
        with ``run-`` are skipped.
    """
    if not runs.is_dir():
        return []
    found = []
    for condition in sorted(runs.iterdir()):
        if condition.is_symlink() or not condition.is_dir():
            raise ResultsError(f"{condition}: expected a condition folder written by neurocur, got "
                               f"{'a symbolic link' if condition.is_symlink() else 'a file'}; remove it")
        for path in sorted(condition.iterdir()):
            if not path.name.startswith("run-"):
                continue
            if run_number(path.name) is None or path.is_symlink() or not path.is_dir():
                why = ("a symbolic link" if path.is_symlink() else "not a folder" if not path.is_dir()
                       else "not spelled run-<NNN> (e.g. run-001)")
                raise ResultsError(f"run folder {path} is {why}: a run folder is a real folder spelled as "
                                   "neurocur writes it (a copied or renamed folder?); remove it")
            found.append(path)
    return found


def digests(folder: Path) -> dict[str, str]:
    """The sha256 of each table (``*.parquet``) of a run folder, by file name.

    Parameters
    ----------
    folder : path
        The run folder.

    Returns
    -------
    dict of str to str
        The hex sha256 of each table, by file name, sorted.
    """
    found = {}
    for path in sorted(Path(folder).glob("*.parquet")):
        h = hashlib.sha256()
        with path.open("rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        found[path.name] = h.hexdigest()
    return found


def agent_digests(folder: Path) -> dict[str, str]:
    """The sha256 of each file of a run folder's saved agent (``agent/``), by name; empty without one.
    ResultsError for a link in the agent's place or in it (never followed).

    Parameters
    ----------
    folder : path
        The run folder.

    Returns
    -------
    dict of str to str
        The hex sha256 of each file of ``agent/``, by name, sorted.
    """
    agent = Path(folder) / AGENT
    try:
        fd = open_real_dir(agent)
        if fd is None:
            return {}
        try:
            return {name: hashlib.sha256(read_own(agent / name, dir_fd=fd)).hexdigest()
                    for name in sorted(os.listdir(fd))}
        finally:
            os.close(fd)
    except UnsafePath as exc:
        raise ResultsError(f"{exc}; remove this run folder") from None


def file_digests(folder: Path) -> dict:
    """What ``run.json`` records of a run folder's files: ``tables`` (:func:`digests`) and, when it
    keeps a saved agent, ``agent`` (:func:`agent_digests`).

    Parameters
    ----------
    folder : path
        The run folder (or the temporary folder it is written in).

    Returns
    -------
    dict
        ``{"tables": ..., "agent": ...}``, without ``agent`` when it keeps none.
    """
    agent = agent_digests(folder)
    return {"tables": digests(folder), **({"agent": agent} if agent else {})}


def check_run_info(folder: Path, info: Mapping, condition: str, run: int, config: Mapping | None) -> tuple | None:
    """Check the ``run.json`` (``info``) of ``folder``, run ``run`` of ``condition`` by its path.

    Returns ``(condition, run)`` as the ``run.json`` says when they differ from the path (the
    caller names a copied or renamed folder), else None. Raises ResultsError for a ``run.json``
    without a proper ``condition`` or ``run``, and, when the folder's ``config.toml`` is given
    and was written by the store (it records ``code``), for a seed, steps or tables digest
    that is missing or disagrees (the digest may be missing in a folder written before run.json
    recorded it).

    Parameters
    ----------
    folder : path
        The run folder.
    info : mapping
        Its ``run.json`` as read ([`read_run_info`][neurocur.results.runinfo.read_run_info]).
    condition : str
        The condition its path names.
    run : int
        The run its path names.
    config : mapping or None
        The results folder's ``config.toml`` as read; None (or one without ``code``) checks only the
        condition and run.

    Returns
    -------
    tuple or None
        ``(condition, run)`` as ``run.json`` says when they differ from the path, else None.

    Raises
    ------
    ResultsError
        For a ``run.json`` that fails a check, naming the file and the key.
    """
    where = Path(folder) / "run.json"
    said_condition, said_run = info.get("condition"), info.get("run")
    if not isinstance(said_condition, str):
        raise ResultsError(f"{where}: key 'condition': expected the run's condition (a string), got "
                           f"{_describe(said_condition)}; remove this run folder")
    if isinstance(said_run, bool) or not isinstance(said_run, int):
        raise ResultsError(f"{where}: key 'run': expected the run's number (an integer), got "
                           f"{_describe(said_run)}; remove this run folder")
    if (said_condition, said_run) != (condition, run):
        return said_condition, said_run
    if not config or "code" not in config:
        return None
    seeds = config.get("seeds") if isinstance(config.get("seeds"), Mapping) else {}
    expected = {"steps": config.get("steps"),
                "seed": {"entropy": seeds.get("entropy"), "spawn_key": run_spawn_key(seeds, run)}}
    for key, value in expected.items():
        if info.get(key) != value:
            raise ResultsError(f"{where}: key '{key}': expected {value!r} as this folder's config.toml says, got "
                               f"{_describe(info.get(key))} (a run of another experiment?); remove this run folder")
    if info.get("agent") is not None and info["agent"] != agent_digests(folder):
        raise ResultsError(f"{where}: key 'agent': expected the sha256 of the saved agent's files as written, got "
                           "other digests (its agent/ was changed or removed since the run was written?); remove this "
                           "run folder")
    recorded, actual = info.get("tables"), digests(folder)
    if recorded is None and not _digests_recorded(config):
        return None  # a folder written before run.json recorded its tables' digest
    if recorded != actual:
        changed = sorted(set(actual) ^ set(recorded)) if isinstance(recorded, Mapping) else []
        changed += sorted(n for n in actual if isinstance(recorded, Mapping) and n in recorded
                          and recorded[n] != actual[n])
        what = ", ".join(changed) if changed else "its tables"
        raise ResultsError(f"{where}: key 'tables': expected the sha256 of the run's tables as written, got "
                           f"{'nothing' if recorded is None else 'other digests'} ({what} changed since the run was "
                           "written?); remove this run folder")
    return None


def _digests_recorded(config: Mapping) -> bool:
    """Whether the folder's runs were written by a store that records table digests (its code
    fingerprints, written by the same version, list the plug-ins)."""
    return any(isinstance(code, Mapping) and "plugins" in code for code in config.get("code", []))


def _describe(value) -> str:
    return "nothing (the key is missing)" if value is None else f"{value!r} ({type(value).__name__})"
