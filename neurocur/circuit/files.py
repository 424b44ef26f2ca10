"""Reading configuration files that extend one another, and a circuit file's tables.

:func:`read_chain` is the one reader of ``extends`` chains, for circuit files and experiment
files alike: each file of the chain is read once, checked for unknown top-level keys, and kept
as a :class:`Layer` (its table and its path), so that what each file wrote keeps its file
(relative paths resolve against it, errors name it). What the layers mean is the caller's: a
circuit's tables are merged here (:func:`read_circuit_file`), an experiment's by
:mod:`neurocur.experiments.resolve`.

The circuit format is described in :mod:`neurocur.circuit`; this module only reads and merges
the files (``regions``, ``edges``, ``lesion``, ``replace``), checking the shape of each table.
What the tables mean (region types, parameters, edges) is checked by
:class:`~neurocur.circuit.Circuit`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..config import ConfigError, describe
from ..regions.pharmacology import DRUGS
from ..tables import check_keys, deep_merge, load_toml, require, resolve_file

__all__ = ["CIRCUIT_KEYS", "Layer", "add_tables", "circuit_tables", "read_chain", "read_circuit_file"]

#: the top-level keys of a circuit file
CIRCUIT_KEYS = ("description", "extends", "regions", "edges", "lesion", "replace")


@dataclass(frozen=True)
class Layer:
    """One file of an ``extends`` chain: its parsed table and its path.

    Parameters
    ----------
    raw : dict
        The file's parsed table.
    path : Path
        The file.
    """

    raw: dict
    path: Path

    @property
    def here(self) -> Path:
        """The folder that this file's relative paths start from."""
        return self.path.parent


def read_chain(path, kind: str, keys, *, read: dict | None = None, chain: tuple[Path, ...] = ()) -> list[Layer]:
    """The files of ``path``'s ``extends`` chain, the furthest base first and ``path`` last, each
    checked for keys outside ``keys``. ``kind`` (``"circuit"``, ``"experiment"``) is the kind of file
    an ``extends`` value names: a path relative to the file, or the name of a shipped one
    (:func:`~neurocur.tables.resolve_file`). ``read``: the files read so far (path → table), so
    that chains sharing a base read it once.

    Parameters
    ----------
    path : str or Path
        The file.
    kind : str
        The kind of file an ``extends`` names.
    keys : collection of str
        The top-level keys a file may have.
    read : dict, optional
        The files read so far (path to table).
    chain : tuple of Path
        The files that extend this one (a cycle is refused).

    Returns
    -------
    list of Layer
        The chain, the furthest base first.
    """
    path = Path(path).resolve()
    read = {} if read is None else read
    if path not in read:
        read[path] = load_toml(path)
        check_keys(read[path], keys, source=path)
    raw = read[path]
    if "extends" not in raw:
        return [Layer(raw, path)]
    article = "an" if kind[0] in "aeiou" else "a"
    base = require(raw, "extends", str, source=path, expected=f"{article} {kind} file path or name (string)")
    base_path = resolve_file(base, path.parent, kind, source=path, key="extends").resolve()
    if not base_path.is_file():
        raise ConfigError(path, "extends", f"an existing {kind} file", f"{base!r} (no such file: {base_path})")
    if base_path in (*chain, path):
        raise ConfigError(path, "extends", f"a chain of {kind} files without a loop",
                          " -> ".join(p.name for p in (*chain, path, base_path)))
    return [*read_chain(base_path, kind, keys, read=read, chain=chain + (path,)), Layer(raw, path)]


def circuit_tables(circuit) -> tuple[Path, dict]:
    """``(path, tables)`` of a circuit file: ``circuit`` is a file path or the name of a shipped
    circuit (:func:`~neurocur.tables.resolve_file`), its tables as :func:`read_circuit_file` reads them.

    Parameters
    ----------
    circuit : str or Path
        A circuit file or a shipped circuit's name.

    Returns
    -------
    tuple of (Path, dict)
        The file and its tables.
    """
    path = resolve_file(circuit, Path(), "circuit", source=circuit, key=None)
    return path, read_circuit_file(path)


def read_circuit_file(path: Path, *, read: dict | None = None) -> dict:
    """Read a circuit file, resolving ``extends``; tag every table with its file and key. ``read``:
    as :func:`read_chain`'s.

    Parameters
    ----------
    path : Path
        The circuit file.
    read : dict, optional
        The files read so far (path to table).

    Returns
    -------
    dict
        Its tables, each tagged with its file and key.
    """
    data = {"regions": {}, "edges": [], "lesion": [], "replace": {}}
    for layer in read_chain(path, "circuit", CIRCUIT_KEYS, read=read):
        add_tables(data, layer.raw, layer.path)
    return data


def add_tables(data: dict, raw: dict, source, prefix: str = "") -> dict:
    """``data`` (tables read so far) with the ``regions``, ``edges``, ``lesion`` and ``replace``
    tables of ``raw`` added as a file extending them would add them, each tagged with ``source``
    and its key (``prefix`` before it: an experiment condition's ``"conditions.NAME."``).

    Parameters
    ----------
    data : dict
        The tables read so far.
    raw : dict
        A file's parsed table.
    source : str or Path
        The file, tagged on each table.
    prefix : str
        The dotted path before each key.

    Returns
    -------
    dict
        The tables with ``raw``'s added.
    """
    regions = require(raw, "regions", dict, source=source, prefix=prefix.rstrip("."),
                      expected="a table of regions", default={})
    for name, table in regions.items():
        if not isinstance(table, dict):
            raise ConfigError(source, f"{prefix}regions.{name}", "a table with 'type' and 'params'", describe(table))
        merged = deep_merge(data["regions"].get(name, {}), table)
        merged["_origin"] = source
        data["regions"][name] = merged
    for field_, kind in (("edges", "edge"), ("lesion", "lesion")):
        items = require(raw, field_, list, source=source, prefix=prefix.rstrip("."),
                        expected=f"an array of {kind} tables ([[{field_}]])", default=[])
        for i, table in enumerate(items):
            key = f"{prefix}{field_}[{i}]"
            if not isinstance(table, dict):
                raise ConfigError(source, key, f"a {kind} table", describe(table))
            if field_ == "lesion":
                check_keys(table, ("region", "how", *{f for d in DRUGS.values() for f in d.__dataclass_fields__}),
                           source=source, prefix=key, required=("region", "how"))
                for f in ("region", "how"):
                    require(table, f, str, source=source, prefix=key, expected="a name (string)")
            data[field_].append({**table, "_origin": source, "_key": key})
    replace = require(raw, "replace", dict, source=source, prefix=prefix.rstrip("."),
                      expected="a table of replacements", default={})
    for name, table in replace.items():
        if not isinstance(table, dict):
            raise ConfigError(source, f"{prefix}replace.{name}", "a table with 'type' and 'params'", describe(table))
        data["replace"][name] = {**table, "_origin": source, "_key": f"{prefix}replace.{name}"}
    return data
