"""Configuration helpers: TOML loading, errors that name the file and key, typed parameters.

Every configuration problem raises :class:`ConfigError`, a ``ValueError`` whose message
reads ``"<file>: key '<dotted.key>': expected <...>, got <...>"``, so a user can go
straight to the offending line. Circuits (``circuits/*.toml``) and experiments
(``experiments/*.toml``) both use these helpers.

Parameters of regions (and of anything else configured from a file) are frozen
dataclasses whose fields are declared with :func:`param`; :func:`check_params`
validates type and range, and :func:`make_params` builds an instance from a TOML table.
Loading a configuration never executes code.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

__all__ = [
    "ConfigError",
    "ParamSpec",
    "param",
    "check_params",
    "make_params",
    "params_to_dict",
    "load_toml",
    "check_keys",
    "require",
    "deep_merge",
    "describe",
]


def describe(value) -> str:
    """Short description of a configuration value for error messages: ``-1 (int)``."""
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{text} ({type(value).__name__})"


class ConfigError(ValueError):
    """A configuration error that names the file, the dotted key and what was expected.

    ``source`` is the file (or a label such as ``"<python>"``), ``key`` the dotted key
    (``None`` for the whole file), ``expected`` what would have been valid, ``got`` what
    was found (already described as text).
    """

    def __init__(self, source, key: str | None, expected: str, got: str):
        self.source = str(source)
        self.key = key
        self.expected = expected
        self.got = got
        where = f"{self.source}: key '{key}'" if key else self.source
        super().__init__(f"{where}: expected {expected}, got {got}")

    def relocated(self, source=None, prefix: str | None = None) -> "ConfigError":
        """The same error reported from another file and/or under a key prefix."""
        key = self.key
        if prefix:
            key = f"{prefix}.{key}" if key else prefix
        return ConfigError(self.source if source is None else source, key, self.expected, self.got)


# --------------------------------------------------------------------------- files


def load_toml(path) -> dict:
    """Read a TOML file into a dict; a missing file or a syntax error is a ConfigError."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ConfigError(path, None, "an existing TOML file", "no such file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(path, None, "valid TOML", f"a syntax error ({exc})") from None


def check_keys(table: Mapping, allowed, *, source, prefix: str = "", required=()) -> None:
    """Raise ConfigError for a key of ``table`` outside ``allowed`` or a missing required key."""
    for key in required:
        if key not in table:
            raise ConfigError(source, _join(prefix, key), "this key to be present", "nothing")
    allowed = tuple(allowed)
    for key in table:
        if key not in allowed:
            raise ConfigError(source, _join(prefix, key), f"one of the keys {list(allowed)}", "an unknown key")


_MISSING = object()


def require(table: Mapping, key: str, types, *, source, prefix: str = "", expected: str, default=_MISSING):
    """Return ``table[key]`` checked against ``types`` (bool never passes for int/float)."""
    if key not in table:
        if default is not _MISSING:
            return default
        raise ConfigError(source, _join(prefix, key), expected, "nothing (the key is missing)")
    value = table[key]
    types = types if isinstance(types, tuple) else (types,)
    if (isinstance(value, bool) and bool not in types) or not isinstance(value, types):
        raise ConfigError(source, _join(prefix, key), expected, describe(value))
    return value


def deep_merge(base: Mapping, override: Mapping) -> dict:
    """A new dict: ``override`` merged into ``base``; nested tables merge, other values replace."""
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = value
    return out


def _join(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


# --------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class ParamSpec:
    """Type and range of one parameter.

    ``kind`` is ``float``, ``int``, ``bool`` or ``str``. Numbers may be bounded by
    ``low``/``high`` (closed unless ``low_open``/``high_open``). ``choices`` lists the
    accepted strings (for ``kind=str``, or as extra accepted values of a numeric
    parameter, e.g. ``gamma = "auto"``). ``optional`` accepts ``None``.
    """

    kind: type
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] = ()
    optional: bool = False

    def expected(self) -> str:
        parts = []
        if self.kind is str:
            parts.append("one of " + ", ".join(repr(c) for c in self.choices))
        else:
            text = {float: "a number", int: "an integer", bool: "a boolean (true/false)"}[self.kind]
            bounds = []
            if self.low is not None:
                bounds.append(f"{'>' if self.low_open else '>='} {self.low:g}")
            if self.high is not None:
                bounds.append(f"{'<' if self.high_open else '<='} {self.high:g}")
            if bounds:
                text += " " + " and ".join(bounds)
            parts.append(text)
            parts += [repr(c) for c in self.choices]
        if self.optional:
            parts.append("None (omit the key)")
        return " or ".join(parts)

    def coerce(self, value):
        """Return the value converted to ``kind``, or raise ``ValueError`` (message: expected)."""
        if value is None and self.optional:
            return None
        if isinstance(value, str) and value in self.choices:
            return value
        ok = False
        if self.kind is bool:
            ok = isinstance(value, (bool, np.bool_))
            value = bool(value) if ok else value
        elif self.kind is int:
            ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
            value = int(value) if ok else value
        elif self.kind is float:
            ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
            value = float(value) if ok else value
            ok = ok and math.isfinite(value)
        if ok and self.kind in (int, float):
            if self.low is not None and (value < self.low or (self.low_open and value == self.low)):
                ok = False
            if self.high is not None and (value > self.high or (self.high_open and value == self.high)):
                ok = False
        if not ok:
            raise ValueError(self.expected())
        return value


def param(default, kind: type, *, low=None, high=None, low_open=False, high_open=False,
          choices=(), optional=False, doc: str = ""):
    """A dataclass field carrying a :class:`ParamSpec` (use inside a frozen dataclass)."""
    spec = ParamSpec(kind, low, high, low_open, high_open, tuple(choices), optional)
    return field(default=default, metadata={"spec": spec, "doc": doc})


def check_params(obj, *, source=None) -> None:
    """Validate (and coerce in place) every :func:`param` field of a frozen dataclass.

    Meant to be called from ``__post_init__``. Raises ConfigError naming the field.
    """
    source = source or type(obj).__name__
    for f in dataclasses.fields(obj):
        spec = f.metadata.get("spec")
        if spec is None:
            continue
        value = getattr(obj, f.name)
        try:
            coerced = spec.coerce(value)
        except ValueError as exc:
            raise ConfigError(source, f.name, str(exc), describe(value)) from None
        if coerced is not value:
            object.__setattr__(obj, f.name, coerced)


def make_params(cls, table: Mapping | None, *, source, prefix: str):
    """Build the parameter dataclass ``cls`` from a TOML table; errors name file and key."""
    table = dict(table or {})
    names = [f.name for f in dataclasses.fields(cls)]
    for key in table:
        if key not in names:
            raise ConfigError(source, _join(prefix, key), f"a parameter of {cls.__qualname__} ({', '.join(names)})",
                              "an unknown parameter")
    try:
        return cls(**table)
    except ConfigError as exc:
        raise ConfigError(source, _join(prefix, exc.key), exc.expected, exc.got) from None


def params_to_dict(obj) -> dict[str, Any]:
    """The parameters as a plain dict, ``None`` values left out (TOML has no null)."""
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj) if getattr(obj, f.name) is not None}
