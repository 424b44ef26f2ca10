"""Sensory worlds: multi-context worlds with a gymnasium-like API, registered by type name.

``synthetic`` (:mod:`.synthetic`, section 4.1: mixed driving forces, :mod:`.sources`) and
``icub`` (:mod:`.icub`, section 4.2: MuJoCo episodes, :mod:`.icub_data`,
:mod:`.icub_scene`). Importing this package imports every module in it, so a world class
decorated with ``@register_world("name")`` in a new file here is available by its type
name; third-party worlds come from the entry-point group ``neurocur.worlds``.
"""

import importlib
import pkgutil

from .base import WORLDS, Episode, SourceSpec, World, register_world

for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_module.name}")


def build_world(table) -> World:
    """The world of a validated world table (``type`` defaults to ``"synthetic"``)."""
    return WORLDS.get(table.get("type", "synthetic")).from_table(table)


def prepare_world(table) -> None:
    """Prepare the world of ``table`` once, before worker processes build it (:meth:`World.prepare`)."""
    WORLDS.get(table.get("type", "synthetic")).prepare(table)


__all__ = ["WORLDS", "Episode", "SourceSpec", "World", "build_world", "prepare_world", "register_world"]
