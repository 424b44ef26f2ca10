"""Reading a circuit file: its tables, following ``extends``, each tagged with its file and key.

The format is described in :mod:`neurocur.circuit`; this module only reads and merges the
files (``regions``, ``edges``, ``lesion``, ``replace``), checking the shape of each table.
What the tables mean (region types, parameters, edges) is checked by
:class:`~neurocur.circuit.Circuit`.
"""

from __future__ import annotations

from pathlib import Path

from ..config import ConfigError, describe
from ..regions.pharmacology import DRUGS
from ..tables import check_keys, deep_merge, load_toml, require, resolve_file

__all__ = ["add_tables", "circuit_tables", "read_circuit_file"]


def circuit_tables(circuit) -> tuple[Path, dict]:
    """``(path, tables)`` of a circuit file: ``circuit`` is a file path or the name of a shipped
    circuit (:func:`~neurocur.tables.resolve_file`), its tables as :func:`read_circuit_file` reads them."""
    path = resolve_file(circuit, Path(), "circuit", source=circuit, key=None)
    return path, read_circuit_file(path)


def read_circuit_file(path: Path, chain: tuple = ()) -> dict:
    """Read a circuit file, resolving ``extends``; tag every table with its file and key."""
    path = path.resolve()
    if path in chain:
        raise ConfigError(path, "extends", "a chain of files without a loop",
                          " -> ".join(p.name for p in chain + (path,)))
    raw = load_toml(path)
    check_keys(raw, ("description", "extends", "regions", "edges", "lesion", "replace"), source=path)
    if "extends" in raw:
        base_name = require(raw, "extends", str, source=path, expected="a circuit file path or name (string)")
        data = read_circuit_file(resolve_file(base_name, path.parent, "circuit", source=path, key="extends"), chain + (path,))
    else:
        data = {"regions": {}, "edges": [], "lesion": [], "replace": {}}
    return add_tables(data, raw, path)


def add_tables(data: dict, raw: dict, source, prefix: str = "") -> dict:
    """``data`` (tables read so far) with the ``regions``, ``edges``, ``lesion`` and ``replace``
    tables of ``raw`` added as a file extending them would add them, each tagged with ``source``
    and its key (``prefix`` before it: an experiment condition's ``"conditions.NAME."``)."""
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
