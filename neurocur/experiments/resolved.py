"""What the entrance's first pass (:mod:`.resolve`) makes: an experiment's values, each with where it was written.

Every value is kept as an :class:`Entry`: the value, the file (or ``--set KEY``) that wrote it,
its key there and the folder its relative paths start from, so that an error found by a later
pass (:mod:`.expand`, :mod:`.build`) names that file and key. A :class:`ConditionTable` is one
checked ``[conditions.NAME]`` table, and :class:`Resolved` the whole experiment: its files'
``extends`` chain and the command line's settings applied.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

__all__ = ["ConditionTable", "Entry", "Resolved"]


@dataclass(frozen=True)
class Entry:
    """A value and where it was written.

    Parameters
    ----------
    value : object
        The value.
    source : path or str
        The file that wrote it, or the command line (``--set KEY``; ``--set`` for its world values).
    key : str or None
        Its dotted key in ``source`` (a world table's: the table's prefix, e.g. ``world`` or
        ``conditions.NAME.world``); None for a command-line value that ``source`` names.
    here : path
        The folder its relative paths start from (the file's, or the working directory).
    """

    value: object
    source: object
    key: str | None
    here: Path


@dataclass(frozen=True)
class ConditionTable:
    """One ``[conditions.NAME]`` table, checked: its circuit file (the command line's, its own or
    the files'), its own ``REGION.param`` overrides and world table, and its circuit variant
    (``replace``, ``edges``, ``lesion``).

    Parameters
    ----------
    name : str
        The condition's name (``default`` for an experiment without ``[conditions]``).
    description : str
        What the condition is (empty when not given).
    circuit : path
        Its circuit file, resolved.
    params : dict of str to Entry
        Its own ``"REGION.param"`` overrides, by flat key.
    world : Entry
        Its own world table (empty when not given).
    variant : dict
        Its ``replace``, ``edges`` and ``lesion`` tables, as written.
    source : path
        The file whose ``[conditions]`` table this is.
    fit : tuple of str
        The ``"REGION.param"`` keys that ``neurocur fit`` fits when none is given (the model's free parameters).
    """

    name: str
    description: str
    circuit: Path
    params: dict[str, Entry]
    world: Entry
    variant: dict
    #: the file whose ``[conditions]`` table this is
    source: Path
    #: the ``"REGION.param"`` keys that ``neurocur fit`` fits when none is given (the model's free parameters)
    fit: tuple[str, ...] = ()


@dataclass(frozen=True)
class Resolved:
    """An experiment file with its ``extends`` chain and the command line's settings applied.

    Parameters
    ----------
    path : path
        The experiment file, resolved.
    name : str
        The experiment's name (default: the file's name without ``.toml``).
    description : str
        What it asks (empty when not given).
    runs : int
        The runs of each condition.
    steps : int
        The frames of each run.
    seed : int or None
        The experiment's seed; None when no file, ``--set`` or ``--seed`` gave one.
    world : tuple of Entry
        The files' ``[world]`` tables, the furthest base first.
    world_sets : dict of str to Entry
        The command line's ``world.KEY`` values, by dotted key.
    params : dict of str to Entry
        The files' ``[params]``, by ``"REGION.param"`` key, later files winning.
    set_params : dict of str to Entry
        The command line's ``"REGION.param"`` values, which win over every condition.
    sweep : dict of str to Entry
        Each swept key's values (the last file's ``[sweep]`` and the command line's).
    conditions : dict of str to ConditionTable
        The checked conditions, by name.
    circuits : dict of path to dict
        The tables of every circuit file a condition names, read once.
    control : str or None
        The condition the others are compared with, if the files name one.
    """

    path: Path
    name: str
    description: str
    runs: int
    steps: int
    seed: int | None
    world: tuple[Entry, ...]
    world_sets: dict[str, Entry]
    params: dict[str, Entry]
    set_params: dict[str, Entry]
    sweep: dict[str, Entry]
    conditions: dict[str, ConditionTable]
    circuits: dict[Path, dict]
    control: str | None = None
