"""The region registry: region types by name.

A region class registers itself with a decorator::

    @register("vta.learning_progress")
    class LearningProgressVTA(Region): ...

Circuit files name region types only by these strings, so loading a circuit never
executes code from the file. Third-party packages add region types through the
entry-point group ``neurocur.regions`` (``name = "package.module:Class"``); an entry
point is loaded lazily, the first time its name is asked for and not found among the
built-in regions.
"""

from __future__ import annotations

import importlib
from importlib.metadata import entry_points

__all__ = ["register", "get", "names", "ENTRY_POINT_GROUP", "UnknownRegionType"]

ENTRY_POINT_GROUP = "neurocur.regions"

_REGISTRY: dict[str, type] = {}
_builtins_loaded = False


class UnknownRegionType(KeyError):
    """Raised by :func:`get` for a name that is neither registered nor an entry point."""


def register(name: str):
    """Class decorator: register a Region subclass under ``name`` and set ``cls.type_name``."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"a region type name must be a non-empty string; got {name!r}")

    def decorate(cls):
        previous = _REGISTRY.get(name)
        if previous is not None and previous is not cls and (
            previous.__module__, previous.__qualname__) != (cls.__module__, cls.__qualname__):
            raise ValueError(f"region type {name!r} is already registered by {previous.__module__}.{previous.__qualname__}")
        cls.type_name = name
        _REGISTRY[name] = cls
        return cls

    return decorate


def _load_builtins() -> None:
    global _builtins_loaded
    if not _builtins_loaded:
        _builtins_loaded = True
        importlib.import_module("neurocur.regions")


def get(name: str) -> type:
    """The region class registered as ``name`` (built-ins first, then entry points)."""
    _load_builtins()
    cls = _REGISTRY.get(name)
    if cls is not None:
        return cls
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name == name:
            loaded = ep.load()
            register(name)(loaded)
            return loaded
    raise UnknownRegionType(name)


def names() -> list[str]:
    """Sorted names of the registered region types (entry points not yet loaded included)."""
    _load_builtins()
    found = set(_REGISTRY) | {ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)}
    return sorted(found)
