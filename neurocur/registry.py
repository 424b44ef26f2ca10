"""Registries of named types: region types and world types.

A :class:`Registry` maps a type name to a class. Classes register themselves with its
decorator::

    REGIONS = Registry("region", "neurocur.regions")

    @REGIONS.register("vta.learning_progress")
    class LearningProgressVTA(Region): ...

Configuration files name types only by these strings, so loading a file never executes
code from it. Third-party packages add types through the registry's entry-point group
(``name = "package.module:Class"``); an entry point is loaded lazily, the first time its
name is asked for and not found among the registered types.

This module knows no concrete type: the built-in region types register when
:mod:`neurocur.regions` is imported, the built-in world types when
:mod:`neurocur.contexts` is (each package imports all of its modules), and the layers
that look types up (the circuit, the experiment spec) import those packages.
"""

from __future__ import annotations

from importlib.metadata import entry_points

__all__ = ["Registry", "UnknownType"]


class UnknownType(KeyError):
    """A name that is neither registered nor an entry point of the registry's group."""


class Registry:
    """Named classes of one kind (``"region"``, ``"world"``), plus the entry points of ``group``.

    Parameters
    ----------
    kind : str
        What it registers, named in messages (``"region"``, ``"world"``).
    group : str
        The entry-point group a third-party package registers its classes under.
    """

    def __init__(self, kind: str, group: str):
        self.kind = kind
        self.group = group
        self._types: dict[str, type] = {}

    def register(self, name: str):
        """Class decorator: register the class under ``name`` and set ``cls.type_name``."""
        if not isinstance(name, str) or not name:
            raise ValueError(f"a {self.kind} type name must be a non-empty string; got {name!r}")

        def decorate(cls):
            previous = self._types.get(name)
            if previous is not None and (previous.__module__, previous.__qualname__) != (
                    cls.__module__, cls.__qualname__):
                raise ValueError(f"{self.kind} type {name!r} is already registered by "
                                 f"{previous.__module__}.{previous.__qualname__}")
            cls.type_name = name
            self._types[name] = cls
            return cls

        return decorate

    def get(self, name: str) -> type:
        """The class registered as ``name``, else the entry point of that name (loaded now)."""
        cls = self._types.get(name)
        if cls is not None:
            return cls
        for ep in entry_points(group=self.group):
            if ep.name == name:
                return self.register(name)(ep.load())
        raise UnknownType(name)

    def loaded(self) -> dict[str, type]:
        """``{name: class}`` of the types registered so far (entry points not yet asked for are not)."""
        return dict(self._types)

    def names(self) -> list[str]:
        """Sorted names of the registered types and of the group's entry points (not yet loaded)."""
        return sorted(set(self._types) | {ep.name for ep in entry_points(group=self.group)})

    def __contains__(self, name: str) -> bool:
        return name in self._types or any(ep.name == name for ep in entry_points(group=self.group))

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {self.group!r}, {len(self._types)} types)"
