"""TOML out: a small writer for plain data, and the first difference of two data trees.

The standard library reads TOML (``tomllib``) but does not write it; a results folder's
``config.toml`` is plain data (str, int, float, bool, lists, nested tables), so this
writer covers exactly that.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

__all__ = ["difference_path", "dotted", "dumps_toml", "first_difference"]


def dumps_toml(data: Mapping, *, header: str = "") -> str:
    """A small TOML writer for plain data (str, int, float, bool, lists, nested tables).

    Tables nested in lists are written as inline tables. ``tomllib.loads`` of the result
    equals ``data`` (tuples and Paths come back as lists and strings).

    Parameters
    ----------
    data : mapping
        The plain-data tree (numpy scalars and arrays are written as numbers and lists).
    header : str
        Text written first as ``#`` comment lines, one per line; empty: none.

    Returns
    -------
    str
        The TOML text, ending with a newline.

    Raises
    ------
    TypeError
        For a value of another type, naming it.
    """
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    _write_table(lines, data, ())
    return "\n".join(lines).strip("\n") + "\n"


def _write_table(lines, table: Mapping, path: tuple):
    scalars = {k: v for k, v in table.items() if not isinstance(v, Mapping)}
    tables = {k: v for k, v in table.items() if isinstance(v, Mapping)}
    if path and (scalars or not tables):
        lines.append("")
        lines.append("[" + ".".join(_key(p) for p in path) + "]")
    for key, value in scalars.items():
        lines.append(f"{_key(key)} = {_value(value)}")
    for key, value in tables.items():
        _write_table(lines, value, path + (key,))


def _key(key) -> str:
    key = str(key)
    if key and all(c.isalnum() or c in "-_" for c in key) and key.isascii():
        return key
    return json.dumps(key)


def _value(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(value, (str, Path)):
        return json.dumps(str(value), ensure_ascii=False)
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML: {value!r}")


def first_difference(old, new) -> str | None:
    """The first dotted key at which two plain-data trees differ (None when equal).

    Parameters
    ----------
    old, new : object
        The two trees (mappings, lists and scalars; NaN equals NaN).

    Returns
    -------
    str or None
        The dotted key ([`dotted`][neurocur.results.tomlio.dotted]) of
        [`difference_path`][neurocur.results.tomlio.difference_path].
    """
    path = difference_path(old, new)
    return None if path is None else dotted(path)


def difference_path(old, new, prefix: tuple = ()) -> tuple | None:
    """The path (keys, and list indices as ints) of the first difference of two plain-data
    trees; None when they are equal, ``()`` when they differ at the root.

    Parameters
    ----------
    old, new : object
        The two trees (mappings, lists and scalars; NaN equals NaN; two lists of different lengths
        differ as a whole, at their own path).
    prefix : tuple
        The path of ``old`` and ``new`` in the trees they belong to, prepended to the result.

    Returns
    -------
    tuple or None
        The path of the first difference, in the order of ``old``'s keys then ``new``'s.
    """
    if isinstance(old, Mapping) and isinstance(new, Mapping):
        for key in list(dict.fromkeys([*old, *new])):
            if key not in old or key not in new:
                return (*prefix, key)
            found = difference_path(old[key], new[key], (*prefix, key))
            if found is not None:
                return found
        return None
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        for i, (a, b) in enumerate(zip(old, new)):
            found = difference_path(a, b, (*prefix, i))
            if found is not None:
                return found
        return None
    same = old == new or (isinstance(old, float) and isinstance(new, float) and math.isnan(old) and math.isnan(new))
    return None if same else prefix


def dotted(path: tuple) -> str:
    """A path as a dotted key (list indices as ``[i]``; ``"(root)"`` for the empty path).

    Parameters
    ----------
    path : tuple
        Keys (str) and list indices (int), as [`difference_path`][neurocur.results.tomlio.difference_path] returns them.

    Returns
    -------
    str
        E.g. ``conditions.curious.world.contexts[2]``.
    """
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(root)"
