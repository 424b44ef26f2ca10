"""Sensory worlds: multi-context worlds with gymnasium's seeding, registered by type name.

``synthetic`` (:mod:`.synthetic`, section 4.1: mixed driving forces, :mod:`.sources`),
``icub`` (:mod:`.icub`, section 4.2: MuJoCo episodes, :mod:`.icub_data`,
:mod:`.icub_scene`) and ``gym`` (:mod:`.gym`: contexts made of gymnasium environments);
every world is a ``gymnasium.Env`` through ``world.as_env()`` (:mod:`.env`), and every world type
has a gymnasium id, ``gymnasium.make("neurocur/Synthetic-v0", **params)`` (:func:`make_env`). Shared by the worlds:
:mod:`.rewards` (extrinsic reward per context, ``rewards`` in every world's table) and
:mod:`.learnability` (Ω of every context); the synthetic world's declared sources (files,
sinusoid pairs, noise) are :mod:`.user_sources`. Importing this package imports every module in it, so a world class
decorated with ``@register_world("name")`` in a new file here is available by its type
name; third-party worlds come from the entry-point group ``neurocur.worlds``.
"""

import importlib
import pkgutil

from ..config import make_params
from .base import WORLDS, Episode, SourceSpec, World, register_world
from .env import register_ids

#: the world type of a world table that names none
DEFAULT_WORLD = "synthetic"

for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_module.name}")


def world_params(table, *, source="world table", prefix="world"):
    """``(world class, its Params)`` of a world table (``type`` defaults to :data:`DEFAULT_WORLD`).

    Paths in the table must already be absolute; errors are ConfigErrors naming the key.

    Parameters
    ----------
    table : mapping
        The world table.
    source : str or path
        Where the table came from, for the messages.
    prefix : str
        The keys' prefix in the messages.

    Returns
    -------
    (type, Params)
        The world class and its parameters.
    """
    table = dict(table)
    cls = WORLDS.get(table.pop("type", DEFAULT_WORLD))
    return cls, make_params(cls.Params, table, source=source, prefix=prefix)


def build_world(table) -> World:
    """The world of a world table, e.g. a results folder's ``config.toml`` ``conditions.X.world``.

    Parameters
    ----------
    table : mapping
        The world table (``type`` and the world's parameters).

    Returns
    -------
    World
        The world.
    """
    cls, params = world_params(table)
    return cls.from_params(params)


def make_env(type=DEFAULT_WORLD, *, max_frames=None, render_mode="rgb_array", **params):
    """The world of type ``type`` and ``params`` (the keys of its world table) as a ``gymnasium.Env``
    (:meth:`World.as_env` with ``max_frames`` and ``render_mode``): what ``gymnasium.make`` of a
    world's id calls.

    Parameters
    ----------
    type : str
        The world type (a registered name).
    max_frames : int, optional
        The rows an observation (a visit's frames) is padded to (:meth:`World.as_env`).
    render_mode : str
        The environment's render mode.
    **params
        The keys of the world table.

    Returns
    -------
    gymnasium.Env
        The world as an environment.
    """
    return build_world({"type": type, **params}).as_env(max_frames=max_frames, render_mode=render_mode)


register_ids(WORLDS.loaded(), f"{__name__}:make_env")

__all__ = ["DEFAULT_WORLD", "WORLDS", "Episode", "SourceSpec", "World", "build_world", "make_env", "register_world", "world_params"]
