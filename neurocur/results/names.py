"""Names that become folders of a results folder: condition names and sweep-point labels.

A condition's name is the name of its folder ``OUT/runs/<name>/``, so it is checked when the
experiment is loaded, before anything runs: letters, digits and ``_ - . +`` only, not starting
with a dot, at most :data:`MAX_NAME` characters. Such a name cannot leave ``OUT`` (no
separator, never ``.`` or ``..``) nor hide (no leading dot). The store checks every folder
name it writes the same way (:func:`check_folder_name`), a label's ``@ = , %`` included.

A sweep point's label (:func:`condition_label`) is ``<condition>@KEY=value,KEY=value`` with the
keys in sorted order, so the same ``[sweep]`` with its keys reordered gives the same folders.
Values are written as TOML/JSON literals (strings bare) with every character outside the
safe set percent-encoded (``"d/x.npy"`` → ``d%2Fx.npy``), so two different values never
share a label by their spelling; labels that still coincide (the string ``"1"`` and the
integer ``1``) are a ConfigError naming both points.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping

from neurocur.config import ConfigError, describe

__all__ = ["MAX_NAME", "check_condition_name", "check_folder_name", "condition_label", "point_label"]

#: the longest condition name or label (a folder name is at most 255 bytes on common file systems)
MAX_NAME = 200
_NAME = re.compile(r"[A-Za-z0-9_\-.+]+")
_LABEL = re.compile(r"[A-Za-z0-9_\-.+=,@%]+")
_SAFE_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-.+")


def check_condition_name(name, source, key: str | None) -> str:
    """``name`` if it can name a condition, else a ConfigError (``source``, ``key``).

    Parameters
    ----------
    name : str
        The name.
    source : str or path
        Where the name came from, for the message.
    key : str, optional
        The key that gave it, for the message.

    Returns
    -------
    str
        ``name``.
    """
    return _check(name, _NAME, "_ - . +", source, key)


def check_folder_name(name, source, key: str | None = None) -> str:
    """``name`` if it can be a condition's folder (a name or a sweep point's label), else a ConfigError.

    Parameters
    ----------
    name : str
        The name.
    source : str or path
        Where the name came from, for the message.
    key : str, optional
        The key that gave it, for the message.

    Returns
    -------
    str
        ``name``.
    """
    return _check(name, _LABEL, "_ - . + = , @ %", source, key)


def _check(name, allowed: re.Pattern, chars: str, source, key) -> str:
    if not isinstance(name, str) or not allowed.fullmatch(name) or name.startswith(".") or len(name) > MAX_NAME:
        got = f"{len(name)} characters" if isinstance(name, str) and len(name) > MAX_NAME else describe(name)
        raise ConfigError(source, key, f"a name of at most {MAX_NAME} characters: letters, digits and {chars}, "
                          "not starting with a dot", got)
    return name


def point_label(point: Mapping) -> str:
    """``"KEY=value,KEY=value"``: keys sorted, values as literals (strings bare), percent-encoded.

    Parameters
    ----------
    point : mapping
        The sweep point, ``{KEY: value}``.

    Returns
    -------
    str
        The label.
    """
    def text(v):
        return _encode(v if isinstance(v, str) else json.dumps(v, sort_keys=True))

    return ",".join(f"{_encode(k)}={text(point[k])}" for k in sorted(point))


def condition_label(name: str, point: Mapping, source, taken: Mapping | None = None) -> str:
    """The folder name of condition ``name`` at sweep ``point`` (``name`` alone without a sweep),
    checked (:func:`check_condition_name`) and unique among ``taken`` (label → a condition with
    a ``sweep`` attribute): a collision is a ConfigError naming both points.

    Parameters
    ----------
    name : str
        The condition's name.
    point : mapping
        The sweep point, ``{KEY: value}`` (empty without a sweep).
    source : str or path
        Where the condition came from, for the message.
    taken : mapping of str to Condition, optional
        The labels already given.

    Returns
    -------
    str
        The folder name.
    """
    check_condition_name(name, source, f"conditions.{name}" if name != "default" else None)
    label = f"{name}@{point_label(point)}" if point else name
    if len(label) > MAX_NAME:
        raise ConfigError(source, "sweep", f"sweep points whose labels ({name}@KEY=value,...) have at most "
                          f"{MAX_NAME} characters", f"{len(label)} characters for {dict(point)}")
    other = (taken or {}).get(label)
    if other is not None:
        raise ConfigError(source, "sweep", "sweep points with distinct labels",
                          f"the points {dict(getattr(other, 'sweep', {}))} and {dict(point)}, both labelled {label!r}")
    return label


def _encode(text: str) -> str:
    return "".join(c if c in _SAFE_CHARS else "".join(f"%{b:02X}" for b in c.encode("utf-8")) for c in text)
