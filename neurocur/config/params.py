"""The one parameter system: :class:`ParamSpec` (a parameter's type and range) and the dataclass
fields that carry one. Checking, building and reading parameter dataclasses from TOML tables is
`neurocur.config.param_tables`."""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from .errors import ConfigError, describe, join_key
from .param_tables import make_params, params_to_dict, resolve_paths

__all__ = ["ParamSpec", "param", "spec_param", "learner_param", "param_specs"]


@dataclass(frozen=True)
class ParamSpec:
    """Type and range of one parameter.

    ``kind`` is ``float``, ``int``, ``bool`` or ``str``. Numbers may be bounded by
    ``low``/``high`` (closed unless ``low_open``/``high_open``). ``choices`` lists the
    accepted strings (for ``kind=str``, or as extra accepted values of another kind,
    e.g. ``gamma = "auto"``); a ``str`` without choices is any non-empty string, and
    with ``path`` a file or folder path, which :func:`resolve_paths` makes absolute
    against the folder of the file that gave it. ``classes`` are extra accepted classes whose
    instances pass unchanged (e.g. a number or an ``AmnesicSchedule``). ``optional``
    accepts ``None``.

    Composite kinds, made with :meth:`sequence`, :meth:`table` and :meth:`nested`:
    ``kind=tuple`` (a list of ``item``-checked values, coerced to a tuple; ``length`` or
    ``min_length`` items), ``kind=dict`` (a table from non-empty string names to
    ``item``-checked values) and ``kind=`` a parameter dataclass (a TOML table turned
    into that class by :func:`make_params`, or an instance of it; with ``shorthand``, the
    name of one of its fields, any other value stands for ``{shorthand: value}``).

    Parameters
    ----------
    kind : type
        ``float``, ``int``, ``bool``, ``str``, ``tuple``, ``dict`` or a parameter dataclass.
    low, high : float, optional
        The bounds of a number.
    low_open, high_open : bool
        Whether a bound is excluded.
    choices : tuple of str
        The accepted strings.
    optional : bool
        None is accepted.
    classes : tuple of type
        Extra classes whose instances pass unchanged.
    item : ParamSpec, optional
        The spec of a sequence's or a table's items.
    length : int, optional
        A sequence's exact length.
    min_length : int
        A sequence's shortest length.
    path : bool
        A string is a file or folder path.
    shorthand : str, optional
        The field of a nested dataclass that any other value stands for.
    """

    kind: type
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] = ()
    optional: bool = False
    classes: tuple[type, ...] = ()
    item: ParamSpec | None = None
    length: int | None = None
    min_length: int = 0
    path: bool = False
    shorthand: str | None = None

    def __post_init__(self):
        if self.kind not in (float, int, bool, str, tuple, dict) and not dataclasses.is_dataclass(self.kind):
            raise TypeError(f"ParamSpec kind must be float, int, bool, str, tuple, dict or a dataclass; got {self.kind!r}")
        if (self.item is not None) != (self.kind in (tuple, dict)):
            raise TypeError("ParamSpec needs an item spec exactly for the sequence and table kinds")
        if self.shorthand is not None and self._shorthand_spec() is None:
            raise TypeError(f"ParamSpec shorthand must name a parameter of a dataclass kind; got {self.shorthand!r}")

    @classmethod
    def sequence(cls, item: ParamSpec, *, length: int | None = None, min_length: int = 0,
                 optional: bool = False) -> ParamSpec:
        """A list (or tuple) of values each checked by ``item``, coerced to a tuple."""
        return cls(tuple, item=item, length=length, min_length=min_length, optional=optional)

    @classmethod
    def table(cls, item: ParamSpec, *, optional: bool = False) -> ParamSpec:
        """A table (dict) from non-empty string names to values each checked by ``item``."""
        return cls(dict, item=item, optional=optional)

    @classmethod
    def nested(cls, params_cls: type, *, optional: bool = False, shorthand: str | None = None) -> ParamSpec:
        """A table of the parameters of the frozen dataclass ``params_cls`` (or an instance of it).

        ``shorthand``: a parameter of ``params_cls`` that a value other than a table gives
        on its own (``S-X = "x.npy"`` for ``S-X = { file = "x.npy" }``).
        """
        return cls(params_cls, optional=optional, shorthand=shorthand)

    def _shorthand_spec(self) -> ParamSpec | None:
        if not dataclasses.is_dataclass(self.kind):
            return None
        return {f.name: f.metadata.get("spec") for f in dataclasses.fields(self.kind)}.get(self.shorthand)

    def expected(self) -> str:
        parts = []
        if self.kind is str:
            if self.choices:
                parts.append("one of " + ", ".join(repr(c) for c in self.choices))
            else:
                parts.append("a file or folder path (string)" if self.path else "a non-empty string")
        elif self.kind is tuple:
            if self.length is not None:
                n, count = self.length, f"{self.length} "
            else:
                n, count = self.min_length, f"at least {self.min_length} " if self.min_length else ""
            parts.append(f"a list of {count}{'item' if n == 1 else 'items'}, each {self.item.expected()}")
            parts += [repr(c) for c in self.choices]
        elif self.kind is dict:
            parts.append(f"a table of named items, each {self.item.expected()}")
        elif dataclasses.is_dataclass(self.kind):
            parts.append(f"a table of {self.kind.__name__} parameters")
            if self.shorthand:
                parts.append(f"its {self.shorthand!r} alone ({self._shorthand_spec().expected()})")
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
        parts += [f"{'an' if c.__name__[0] in 'AEIOU' else 'a'} {c.__name__}" for c in self.classes]
        if self.optional:
            parts.append("None (omit the key)")
        return " or ".join(parts)

    def coerce(self, value, *, source="<python>", key: str | None = None):
        """Return the value converted to ``kind``, or raise :class:`ConfigError`.

        The error names ``source`` and ``key`` (for a composite kind, the key of the
        offending item below ``key``: ``points[2]``, ``arms.left``, ``scene.arm_length``).
        """
        if value is None and self.optional:
            return None
        if isinstance(value, str) and value in self.choices:
            return value
        if self.classes and isinstance(value, self.classes):
            return value
        if self.kind is tuple:
            return self._coerce_sequence(value, source, key)
        if self.kind is dict:
            return self._coerce_table(value, source, key)
        if dataclasses.is_dataclass(self.kind):
            if isinstance(value, self.kind):
                return value
            if self.shorthand and not isinstance(value, Mapping):
                value = {self.shorthand: value}
            if isinstance(value, Mapping):
                return make_params(self.kind, value, source=source, prefix=key or "")
            raise ConfigError(source, key, self.expected(), describe(value))
        ok = False
        converted = value
        if self.kind is str:
            ok = isinstance(value, str) and bool(value) and not self.choices
        elif self.kind is bool:
            ok = isinstance(value, (bool, np.bool_))
            converted = bool(value) if ok else value
        elif self.kind is int:
            ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
            converted = int(value) if ok else value
        elif self.kind is float:
            ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
            converted = float(value) if ok else value
            ok = ok and math.isfinite(converted)
        if ok and self.kind in (int, float):
            if self.low is not None and (converted < self.low or (self.low_open and converted == self.low)):
                ok = False
            if self.high is not None and (converted > self.high or (self.high_open and converted == self.high)):
                ok = False
        if not ok:
            raise ConfigError(source, key, self.expected(), describe(value))
        return converted

    def _coerce_sequence(self, value, source, key) -> tuple:
        n = len(value) if isinstance(value, (list, tuple)) else -1
        if n < 0 or (self.length is not None and n != self.length) or n < self.min_length:
            raise ConfigError(source, key, self.expected(), describe(value))
        return tuple(self.item.coerce(v, source=source, key=join_key(key or "", f"[{i}]")) for i, v in enumerate(value))

    def _coerce_table(self, value, source, key) -> dict:
        if not isinstance(value, Mapping):
            raise ConfigError(source, key, self.expected(), describe(value))
        out = {}
        for name, v in value.items():
            if not isinstance(name, str) or not name:
                raise ConfigError(source, key, "a table whose names are non-empty strings", f"the name {name!r}")
            out[name] = self.item.coerce(v, source=source, key=join_key(key or "", name))
        return out

    def resolved(self, value, base_dir: Path):
        """``value`` with its paths made absolute against ``base_dir`` (``~`` expanded); the rest unchanged."""
        if self.path and isinstance(value, str) and value:
            return str((Path(base_dir) / Path(value).expanduser()).resolve())
        if self.kind is tuple and isinstance(value, (list, tuple)):
            return [self.item.resolved(v, base_dir) for v in value]
        if self.kind is dict and isinstance(value, Mapping):
            return {name: self.item.resolved(v, base_dir) for name, v in value.items()}
        if dataclasses.is_dataclass(self.kind) and isinstance(value, Mapping):
            return resolve_paths(self.kind, value, base_dir)
        if self.shorthand and not isinstance(value, self.kind):
            return self._shorthand_spec().resolved(value, base_dir)
        return value

    def plain(self, value):
        """``value`` as plain data (nested parameters as dicts, sequences as lists), for TOML or JSON."""
        if value is None:
            return None
        if self.kind is tuple and isinstance(value, (list, tuple)):
            return [self.item.plain(v) for v in value]
        if self.kind is dict and isinstance(value, Mapping):
            return {name: self.item.plain(v) for name, v in value.items()}
        if dataclasses.is_dataclass(self.kind) and isinstance(value, self.kind):
            return params_to_dict(value)
        return value


def param(default, kind: type, *, low=None, high=None, low_open=False, high_open=False,
          choices=(), optional=False, path=False, doc: str = ""):
    """A dataclass field carrying a :class:`ParamSpec` (use inside a frozen dataclass).

    Parameters
    ----------
    default : object
        The parameter's default.
    kind : type
        ``float``, ``int``, ``bool`` or ``str``.
    low, high : float, optional
        Its bounds.
    low_open, high_open : bool
        Whether a bound is excluded.
    choices : tuple of str
        The accepted strings.
    optional : bool
        None is accepted.
    path : bool
        The value is a file path (made absolute against the file that gives it).
    doc : str
        What the parameter means (the docs' tables).

    Returns
    -------
    dataclasses.Field
        The field.
    """
    spec = ParamSpec(kind, low=low, high=high, low_open=low_open, high_open=high_open, choices=tuple(choices),
                     optional=optional, path=path)
    return spec_param(default, spec, doc=doc)


def spec_param(default, spec: ParamSpec, *, doc: str = ""):
    """A dataclass field carrying a ready :class:`ParamSpec`, e.g. a composite one.

    A table (dict) default is copied for each instance; ``dataclasses.MISSING`` makes the
    parameter required.

    Parameters
    ----------
    default : object
        The parameter's default (``dataclasses.MISSING``: required).
    spec : ParamSpec
        Its type and range.
    doc : str
        What the parameter means.

    Returns
    -------
    dataclasses.Field
        The field.
    """
    metadata = {"spec": spec, "doc": doc}
    if isinstance(default, dict):
        return field(default_factory=lambda: dict(default), metadata=metadata)
    return field(default=default, metadata=metadata)


def learner_param(owner, name: str, default, *, doc: str = ""):
    """A dataclass field checked by the spec that ``owner`` declares for its parameter ``name``.

    ``owner`` declares its parameters as fields too (the learners of :mod:`neurocur.learn`
    do, :func:`param_specs`), so a parameter passed on to a learner accepts exactly what
    the learner accepts: ``mca_rate: float = learner_param(IncSFA, "mca_rate", 0.05,
    doc="MCA learning rate")`` in a region, ``eig_cutoff: float = learner_param(CCIPCA,
    "eig_cutoff", 1e-3)`` in IncSFA, which whitens with a CCIPCA.

    Parameters
    ----------
    owner : type
        The class that declares the parameter (a learner).
    name : str
        The parameter's name there.
    default : object
        Its default here.
    doc : str
        What the parameter means.

    Returns
    -------
    dataclasses.Field
        The field.
    """
    return spec_param(default, param_specs(owner)[name], doc=doc)


def param_specs(owner) -> Mapping[str, ParamSpec]:
    """``{name: spec}`` of every field of the dataclass ``owner`` (a class or an instance) that
    carries a spec (made with :func:`param`, :func:`spec_param` or :func:`learner_param`), in
    field order; read-only.

    Parameters
    ----------
    owner : type or object
        A parameter dataclass or an instance.

    Returns
    -------
    mapping of str to ParamSpec
        The specs by field name.
    """
    return _field_specs(owner if isinstance(owner, type) else type(owner))


@functools.cache
def _field_specs(cls: type) -> Mapping[str, ParamSpec]:
    return MappingProxyType({f.name: f.metadata["spec"] for f in dataclasses.fields(cls) if "spec" in f.metadata})
