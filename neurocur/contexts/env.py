"""Any world as a ``gymnasium.Env``.

:class:`WorldEnv` (``world.as_env()``) is a world as a real ``gymnasium.Env``:

* **action**: the context to visit, ``Discrete(n_contexts)``;
* **observation**: the whole visit (an :class:`~.base.Episode`) padded to ``max_frames``
  rows, a ``Dict`` of ``"frames"`` (``Box(0, 1, (max_frames, n_pixels), float64)``, rows
  are time, zeros after the visit), ``"states"`` (``MultiDiscrete``, the context-state of
  each row, 0 after the visit), ``"starts"`` (``MultiBinary``, 1 where an independent
  episode begins) and ``"n_frames"`` (``Discrete(max_frames, start=1)``, the visit's length);
* **reward** the visit's extrinsic reward (:attr:`~.base.Episode.reward`, 0.0 unless the
  world declares ``rewards``, :mod:`.rewards`), never terminated or truncated;
* ``reset(seed=None, options=None)``: a new run of the world, whose first visit is of
  ``options["context"]`` (default 0), with the world's seeding (:mod:`.base`): the env's
  ``np_random`` *is* the world's generator;
* ``render()``: the last frame shown, as an (H, W, 3) ``uint8`` gray image.

Every world type registered when :mod:`neurocur.contexts` is imported also has a gymnasium id,
``neurocur/<Class>-v0`` after its class without the ``World`` suffix (``neurocur/Synthetic-v0``,
``neurocur/ICub-v0``, ...; :func:`register_ids`): ``gymnasium.make(id, **params)`` builds the world
of those parameters (its world table's keys, e.g. ``visit_length=30``; ``max_frames`` and
``render_mode`` go to the env), as ``gymnasium.make("neurocur.contexts:neurocur/Synthetic-v0")``
does without importing neurocur first.

The env knows the world only through its interface (``reset``, ``step``, ``close``,
``np_random`` and the generator it holds, ``n_contexts``, ``n_pixels``, ``n_states``,
``frame_shape``, ``max_frames``), so this module does not import :mod:`.base`, which builds
:meth:`~.base.World.as_env` on it.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

__all__ = ["WorldEnv", "env_id", "register_ids"]


class WorldEnv(gymnasium.Env):
    """A :class:`~.base.World` as a ``gymnasium.Env`` (spaces and seeding: the module docstring).

    ``max_frames``: the observation's rows (default ``world.max_frames``); a visit longer
    than that raises. The env and the world share state: stepping one steps the other.

    Parameters
    ----------
    world : World
        The world to wrap; the env shares its state and its generator.
    max_frames : int, optional
        Rows of the observation, at least 1 (default: ``world.max_frames``; a ``ValueError`` if the
        world does not bound its visits and none is given).
    render_mode : {"rgb_array", None}
        ``"rgb_array"``: ``render()`` returns the last frame shown as an (H, W, 3) ``uint8`` image;
        None: it returns None.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, world, *, max_frames: int | None = None, render_mode: str | None = "rgb_array"):
        length = world.max_frames if max_frames is None else max_frames
        if not (isinstance(length, (int, np.integer)) and length >= 1):
            raise ValueError(f"{type(world).__name__} does not bound its visits: give max_frames (an int >= 1); "
                             f"got {length!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be 'rgb_array' or None; got {render_mode!r}")
        self.world, self.max_frames, self.render_mode = world, int(length), render_mode
        self.action_space = spaces.Discrete(world.n_contexts)
        self.observation_space = spaces.Dict({
            "frames": spaces.Box(0.0, 1.0, (self.max_frames, world.n_pixels), np.float64),
            "states": spaces.MultiDiscrete(np.full(self.max_frames, world.n_states, dtype=np.int64)),
            "starts": spaces.MultiBinary(self.max_frames),
            "n_frames": spaces.Discrete(self.max_frames, start=1),
        })
        self._seed = -1
        self._last = np.zeros(world.n_pixels)

    @property
    def np_random(self) -> np.random.Generator:
        """The world's generator."""
        return self.world.np_random

    @np_random.setter
    def np_random(self, value: np.random.Generator) -> None:
        self.world.np_random = value
        self._seed = -1

    @property
    def _np_random(self) -> np.random.Generator | None:
        return self.world._np_random

    @property
    def np_random_seed(self) -> int:
        """The seed of the last seeded reset, or -1 if the generator was not seeded through :meth:`reset`."""
        return self._seed

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        episode, info = self.world.reset(seed=seed, options=options)
        if seed is not None:
            self._seed = seed
        return self._observe(episode), info

    def step(self, action):
        episode, reward, terminated, truncated, info = self.world.step(action)
        return self._observe(episode), reward, terminated, truncated, info

    def render(self) -> np.ndarray | None:
        """The last frame shown (black before the first reset), as an (H, W, 3) ``uint8`` image."""
        if self.render_mode is None:
            return None
        gray = np.round(self._last.reshape(self.world.frame_shape) * 255.0).astype(np.uint8)
        return np.repeat(gray[:, :, None], 3, axis=2)

    def close(self) -> None:
        self.world.close()

    def _observe(self, episode) -> dict:
        n = len(episode.frames)
        if n > self.max_frames:
            raise RuntimeError(f"a visit of {n} frames is longer than the env's max_frames = {self.max_frames}")
        frames = np.zeros((self.max_frames, self.world.n_pixels))
        frames[:n] = episode.frames
        states = np.zeros(self.max_frames, dtype=np.int64)
        states[:n] = episode.states
        starts = np.zeros(self.max_frames, dtype=np.int8)
        starts[episode.starts] = 1
        self._last = frames[n - 1].copy()
        return {"frames": frames, "states": states, "starts": starts, "n_frames": np.int64(n)}


def env_id(cls: type) -> str:
    """The gymnasium id of the world class ``cls``: ``neurocur/<name>-v0``, the class name without ``World``."""
    return f"neurocur/{cls.__name__.removesuffix('World')}-v0"


def register_ids(worlds: dict[str, type], entry_point: str) -> None:
    """Register :func:`env_id` of every world class of ``worlds`` (``{type name: class}``) with
    gymnasium, made by ``entry_point`` (``"module:function"``) called with ``type=`` the type name.

    Parameters
    ----------
    worlds : dict of str to type
        The world classes to register, by world type name.
    entry_point : str
        ``"module:function"`` that gymnasium calls with ``type=`` the type name (and the ``make``
        keywords) to build the env.
    """
    for name, cls in worlds.items():
        if env_id(cls) not in gymnasium.registry:
            gymnasium.register(env_id(cls), entry_point=entry_point, kwargs={"type": name})
