"""Parameter dataclasses to and from TOML tables: checking a dataclass's fields against their
specs, building one from a table (errors naming the file and dotted key), making its paths absolute,
and writing it back as plain data.

The fields' specs (`neurocur.config.params.ParamSpec`) are read from the dataclass fields' metadata,
so this module does not import the one that declares them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from .errors import ConfigError, join_key

__all__ = ["coerce_params", "check_params", "check_table", "make_params", "resolve_paths", "params_to_dict",
           "path_values"]


def coerce_params(specs: Mapping, values: Mapping, *, source) -> dict:
    """``values`` checked and coerced by ``specs[name]``, by name; errors are ConfigErrors naming the key.

    Parameters
    ----------
    specs : mapping of str to ParamSpec
        The specs by name.
    values : mapping
        The values by name.
    source : str
        The file named in a message.

    Returns
    -------
    dict
        The coerced values.
    """
    return {name: specs[name].coerce(value, source=source, key=name) for name, value in values.items()}


def check_params(obj, *, source=None) -> None:
    """Validate (and coerce in place) every field of a frozen dataclass that carries a spec.

    (Fields made with :func:`param`, :func:`spec_param` or :func:`learner_param`.)

    Meant to be called from ``__post_init__``. Raises ConfigError naming the field.

    Parameters
    ----------
    obj : object
        A frozen parameter dataclass.
    source : str, optional
        The file named in a message.
    """
    source = source or type(obj).__name__
    for f in dataclasses.fields(obj):
        spec = f.metadata.get("spec")
        if spec is None:
            continue
        value = getattr(obj, f.name)
        coerced = spec.coerce(value, source=source, key=f.name)
        if coerced is not value:
            object.__setattr__(obj, f.name, coerced)


def check_table(cls, table: Mapping, *, source, prefix: str) -> None:
    """Check each key of a (partial) table of ``cls`` parameters on its own: known, and of the
    right kind and range. Cross-parameter checks wait for :func:`make_params` on the whole table.

    Parameters
    ----------
    cls : type
        The parameter dataclass.
    table : mapping
        A (partial) table of its parameters.
    source : str
        The file named in a message.
    prefix : str
        The table's dotted path.
    """
    specs = {f.name: f.metadata.get("spec") for f in dataclasses.fields(cls)}
    for key, value in table.items():
        if key not in specs:
            raise ConfigError(source, join_key(prefix, key), f"a parameter of {cls.__qualname__} ({', '.join(specs)})",
                              "an unknown parameter")
        if specs[key] is not None:
            specs[key].coerce(value, source=source, key=join_key(prefix, key))


def resolve_paths(cls, table: Mapping, base_dir) -> dict:
    """A table of ``cls`` parameters with every path parameter made absolute against ``base_dir``.

    Parameters
    ----------
    cls : type
        The parameter dataclass.
    table : mapping
        A table of its parameters.
    base_dir : Path
        The folder a relative path is taken from.

    Returns
    -------
    dict
        The table with absolute paths.
    """
    specs = {f.name: f.metadata.get("spec") for f in dataclasses.fields(cls)}
    return {k: specs[k].resolved(v, base_dir) if specs.get(k) is not None else v for k, v in table.items()}


def make_params(cls, table: Mapping | None, *, source, prefix: str):
    """Build the parameter dataclass ``cls`` from a TOML table; errors name file and key.

    Parameters
    ----------
    cls : type
        The parameter dataclass.
    table : mapping or None
        Its TOML table (None: the defaults).
    source : str
        The file named in a message.
    prefix : str
        The table's dotted path.

    Returns
    -------
    object
        The parameters.
    """
    table = dict(table or {})
    names = [f.name for f in dataclasses.fields(cls)]
    for key in table:
        if key not in names:
            raise ConfigError(source, join_key(prefix, key), f"a parameter of {cls.__qualname__} ({', '.join(names)})",
                              "an unknown parameter")
    try:
        return cls(**table)
    except ConfigError as exc:
        raise ConfigError(source, join_key(prefix, exc.key), exc.expected, exc.got) from None


def path_values(obj) -> list[str]:
    """The values of every path parameter (``ParamSpec(path=True)``) of the parameter
    dataclass ``obj``, in field order, inside lists, tables and nested parameters too.

    Only string values are listed (an array given in place of a file is not a path).

    Parameters
    ----------
    obj : object
        A parameter dataclass.

    Returns
    -------
    list of str
        The path values.
    """
    found: list[str] = []

    def walk(spec, value) -> None:
        if spec.path and isinstance(value, str):
            found.append(value)
        elif spec.kind is tuple and isinstance(value, (list, tuple)):
            for item in value:
                walk(spec.item, item)
        elif spec.kind is dict and isinstance(value, Mapping):
            for item in value.values():
                walk(spec.item, item)
        elif dataclasses.is_dataclass(spec.kind) and isinstance(value, spec.kind):
            found.extend(path_values(value))

    for f in dataclasses.fields(obj):
        if f.metadata.get("spec") is not None:
            walk(f.metadata["spec"], getattr(obj, f.name))
    return found


def params_to_dict(obj) -> dict[str, Any]:
    """The parameters as plain data, ``None`` values left out (TOML has no null).

    Nested parameters become dicts and sequences lists (:meth:`ParamSpec.plain`), so
    :func:`make_params` rebuilds an equal object from the result.

    Parameters
    ----------
    obj : object
        A parameter dataclass.

    Returns
    -------
    dict
        Its parameters as plain data.
    """
    out = {}
    for f in dataclasses.fields(obj):
        value, spec = getattr(obj, f.name), f.metadata.get("spec")
        if value is not None:
            out[f.name] = spec.plain(value) if spec is not None else value
    return out
