"""Any ``gymnasium.Env`` as a world (the other way, any world as an env, is :mod:`.env`).

:class:`GymWorld` (world type ``"gym"``) makes CD-MISFA contexts of gymnasium
environments: context ``i`` is environment ``envs[i]`` (optionally reset with a fixed seed
or fixed options every time), run by an exploration policy (uniform random actions by
default). A visit runs ``visit_length`` steps of that environment, continuing its episode
where the previous visit left it and resetting it when it terminates or is truncated; every
reset inside a visit is a segment start (``Episode.starts``), so no temporal derivative spans
two episodes. The context-state of a row is its step within the environment's episode (0 at
a reset), capped at ``n_states - 1``. A context's source is its environment id as written:
the analysis has no ground truth for them.

An id may come from any package that registers gymnasium environments when imported: name
the package in ``imports`` (``imports = ["neurogym"]``) or prefix the id with it as gymnasium
does (``"neurogym:PerceptualDecisionMaking-v0"``). The modules are imported when the world is
built, never when its parameters are read (:mod:`.gym_ids`).

What a row shows (``observation``):

* ``"render"`` (the default): the environment's ``rgb_array`` render, converted to gray
  (ITU-R BT.601 luma), resized to ``frame_shape`` (``gym_frames.to_frame``) and scaled to [0, 1];
  environments are made with ``render_mode="rgb_array"``.
* ``"vector"``: the observation itself, flattened (``gymnasium.spaces.flatten``: a ``Box``
  row-major, a ``Discrete`` one-hot, a ``Dict`` or ``Tuple`` joined) and scaled to [0, 1] per
  dimension by the bounds of the flattened observation space, ``(x - low) / (high - low)``
  (``gym_frames.VectorScale``). A bound that is infinite, or at least float32's largest value (the
  bound some environments give an unbounded dimension, as gymnasium's CartPole did before 1.0), is
  replaced by the declared ``observation_range = [low, high]``, and values outside the bounds
  are clipped to [0, 1]; an environment with such a dimension and no ``observation_range`` is
  refused. A dimension whose two bounds are equal (a constant) is 0. A fixed scaling, not a running one, so that a frame's value means the same
  observation from a run's first step to its last. No ``render_mode`` is passed; frames are
  (1, size) rows and ``frame_shape`` is not used. Every environment must have observations of
  one size; a non-finite observation is an error.

Per run (:meth:`GymWorld.reset`), the world's generator draws for each context in order
the seed of its environment's first reset and the seed of its action space; after the
first reset an environment's own generator continues (unless the context has a fixed
reset seed).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import gymnasium
import numpy as np
from gymnasium.envs.registration import load_env_creator

from ..config import ConfigError, ParamSpec, check_params, describe, extra, param, spec_param
from .base import Episode, World, register_world
from .gym_frames import VectorScale, to_frame
from .gym_ids import check_ids, import_ids
from .rewards import Rewards, check_rewards, rewards_param

__all__ = ["GymParams", "GymWorld", "random_policy"]


def random_policy(env: gymnasium.Env, observation) -> object:
    """The default exploration policy: a uniform random action from the env's (seeded) action space.

    Parameters
    ----------
    env : gymnasium.Env
        The environment; its action space is seeded by the world once per run.
    observation : object
        The environment's last observation (not read).

    Returns
    -------
    object
        An action sampled uniformly from ``env.action_space``.
    """
    return env.action_space.sample()


def _draws_with_pygame(env_id: str) -> bool:
    """Whether ``env_id`` is one of gymnasium's environments drawn with pygame (the ``gym`` extra)."""
    entry = gymnasium.spec(env_id).entry_point
    return isinstance(entry, str) and entry.startswith(("gymnasium.envs.classic_control", "gymnasium.envs.toy_text"))


_ID = ParamSpec(str)
_IDS = ParamSpec.sequence(_ID, min_length=1)
_OBSERVATIONS = ("render", "vector")


@dataclass(frozen=True)
class GymParams:
    """Parameters of :class:`GymWorld` (an experiment file's ``[world]`` table, ``type = "gym"``).

    The per-context lists (``context_names``, ``reset_seeds``, ``reset_options``, ``rewards``:
    :mod:`.rewards`) have one item per environment of ``envs``; every id must be registered
    with gymnasium, now or once the modules of ``imports`` and of the ids' ``module:`` prefixes
    are imported (when the world is built: :mod:`.gym_ids`).

    Parameters
    ----------
    envs : tuple of str
        The gymnasium environment id of each context (``"module:id"``: import ``module`` first).
    imports : tuple of str, optional
        Modules to import when the world is built, whose import registers ids (e.g. ``neurogym``).
    context_names : tuple of str, optional
        Distinct names, one per environment (default: the ids, a repeated one numbered ``id#k``).
    visit_length : int
        Frames (environment steps) per visit.
    frame_shape : tuple of int
        ``(height, width)`` in pixels of a rendered frame.
    observation : {"render", "vector"}
        What a frame shows: the ``rgb_array`` render, or the observation vector (module docstring).
    observation_range : tuple of float, optional
        Only with ``observation = "vector"``: the ``[low, high]``, low < high, that scales a dimension
        whose bound is unbounded.
    n_states : int
        Context-states: the step in the environment's episode, capped at ``n_states - 1``.
    max_episode_steps : int, optional
        Time limit of the environments' episodes (default: each one's own).
    reset_seeds : tuple of int, optional
        Per context, the seed of every reset of its environment (-1: drawn once per run).
    reset_options : tuple of dict, optional
        Per context, the options (numbers) of every reset of its environment.
    rewards : tuple, optional
        Extrinsic reward per context, a number or a schedule each (``neurocur.contexts.rewards``).
    """

    envs: tuple[str, ...] = spec_param(("CartPole-v1", "Pendulum-v1", "Acrobot-v1"), _IDS,
                                       doc="the gymnasium environment id of each context ('module:id': import module "
                                       "first)")
    imports: tuple[str, ...] | None = spec_param(
        None, ParamSpec.sequence(_ID, min_length=1, optional=True),
        doc="modules to import when the world is built, whose import registers environment ids (e.g. neurogym)")
    context_names: tuple[str, ...] | None = spec_param(
        None, ParamSpec.sequence(_ID, min_length=1, optional=True), doc="distinct names; default the ids")
    visit_length: int = param(100, int, low=1, doc="frames (environment steps) per visit")
    frame_shape: tuple[int, int] = spec_param((20, 20), ParamSpec.sequence(ParamSpec(int, low=1), length=2),
                                              doc="(height, width) in pixels of a rendered frame")
    observation: str = param("render", str, choices=_OBSERVATIONS,
                             doc="what a frame shows: the rgb_array render, or the observation vector")
    observation_range: tuple[float, float] | None = spec_param(
        None, ParamSpec.sequence(ParamSpec(float), length=2, optional=True),
        doc="observation = 'vector': the [low, high] that scales a dimension whose space bound is unbounded")
    n_states: int = param(20, int, low=1, doc="context-states: the step in the environment's episode, capped")
    max_episode_steps: int | None = param(None, int, low=1, optional=True,
                                          doc="time limit of the environments' episodes; default each one's own")
    reset_seeds: tuple[int, ...] | None = spec_param(
        None, ParamSpec.sequence(ParamSpec(int, low=-1), min_length=1, optional=True),
        doc="per context, the seed of every reset of its environment (-1: drawn once per run)")
    reset_options: tuple[dict, ...] | None = spec_param(
        None, ParamSpec.sequence(ParamSpec.table(ParamSpec(float)), min_length=1, optional=True),
        doc="per context, the options (numbers) of every reset of its environment")
    rewards: tuple | None = rewards_param()

    def __post_init__(self):
        check_params(self)
        where, n = type(self).__name__, len(self.envs)
        check_ids(self.envs, self.imports, where)
        if self.observation_range is not None:
            if self.observation != "vector":
                raise ConfigError(where, "observation_range", "no range unless observation = 'vector'",
                                  describe(list(self.observation_range)))
            if not self.observation_range[0] < self.observation_range[1]:
                raise ConfigError(where, "observation_range", "[low, high] with low < high",
                                  describe(list(self.observation_range)))
        for key in ("context_names", "reset_seeds", "reset_options"):
            value = getattr(self, key)
            if value is not None and len(value) != n:
                raise ConfigError(where, key, f"{n} items (one per environment)", describe(value))
        if self.context_names is not None and len(set(self.context_names)) != n:
            raise ConfigError(where, "context_names", f"{n} distinct names", describe(self.context_names))
        check_rewards(self, n, self.context_names or _default_names(self.envs))


def _default_names(ids: Sequence[str]) -> tuple[str, ...]:
    """The ids, a repeated id numbered by occurrence (``CartPole-v1#1``, ``CartPole-v1#2``)."""
    seen: dict[str, int] = {}
    names = []
    for env_id in ids:
        seen[env_id] = seen.get(env_id, 0) + 1
        names.append(env_id if ids.count(env_id) == 1 else f"{env_id}#{seen[env_id]}")
    return tuple(names)


@register_world("gym")
class GymWorld(World):
    """Contexts that each show a gymnasium environment run by an exploration policy.

    Parameters as :class:`GymParams` (or ``params=``), plus ``policy``, a function
    ``(env, observation) -> action`` (default :func:`random_policy`; the world seeds each
    environment's action space per run, so a policy drawing from it is reproducible).
    With ``observation="render"`` environments are made with ``render_mode="rgb_array"``;
    one that cannot render so is an error. Building the world imports the modules its
    parameters name. Frames, context-states and seeding: the module docstring.

    Parameters
    ----------
    envs : sequence of str
        The gymnasium environment id of each context (``"module:id"`` imports ``module`` first).
    imports : sequence of str, optional
        Modules to import when the world is built, whose import registers environment ids.
    context_names : sequence of str, optional
        Distinct context names, one per environment (default: the ids, a repeated id numbered
        ``id#1``, ``id#2``).
    visit_length : int
        Frames (environment steps) per visit.
    frame_shape : sequence of int
        ``(height, width)`` in pixels of a rendered frame (``observation="render"``).
    observation : {"render", "vector"}
        What a frame shows: the environment's ``rgb_array`` render, or its observation vector
        scaled to [0, 1] (module docstring).
    observation_range : sequence of float, optional
        ``observation="vector"``: the ``[low, high]`` that scales a dimension whose space bound is
        unbounded.
    n_states : int
        Context-states: a row's step in its environment's episode, capped at ``n_states - 1``.
    max_episode_steps : int, optional
        Time limit of the environments' episodes (default: each environment's own).
    reset_seeds : sequence of int, optional
        Per context, the seed of every reset of its environment; -1 draws it once per run.
    reset_options : sequence of dict, optional
        Per context, the options (numbers) of every reset of its environment.
    rewards : sequence, optional
        The extrinsic reward of each context's visits (``neurocur.contexts.rewards``); None pays 0.
    policy : callable
        ``(env, observation) -> action``, the exploration policy of every environment (default
        ``random_policy``).
    params : GymParams, optional
        The parameters as one object; when given, the keywords from ``envs`` to ``rewards`` are
        not read.
    """

    Params = GymParams

    def __init__(
        self,
        envs: Sequence[str] = GymParams.envs,
        *,
        imports: Sequence[str] | None = None,
        context_names: Sequence[str] | None = None,
        visit_length: int = 100,
        frame_shape: Sequence[int] = (20, 20),
        observation: str = "render",
        observation_range: Sequence[float] | None = None,
        n_states: int = 20,
        max_episode_steps: int | None = None,
        reset_seeds: Sequence[int] | None = None,
        reset_options: Sequence[dict] | None = None,
        rewards: Sequence | None = None,
        policy: Callable[[gymnasium.Env, object], object] = random_policy,
        params: GymParams | None = None,
    ) -> None:
        if params is None:
            params = GymParams(envs=envs, imports=imports, context_names=context_names, visit_length=visit_length,
                               frame_shape=frame_shape, observation=observation, observation_range=observation_range,
                               n_states=n_states, max_episode_steps=max_episode_steps, reset_seeds=reset_seeds,
                               reset_options=reset_options, rewards=rewards)
        p = self.params = params
        self.rewards = Rewards.of(p.rewards)
        self.context_names = p.context_names or _default_names(p.envs)
        self.source_names = p.envs
        self.n_states = p.n_states
        self.visit_length = self.max_frames = p.visit_length
        self.policy = policy
        ids = import_ids(p.envs, p.imports, type(p).__name__)
        self.envs: list[gymnasium.Env] = []
        try:
            if p.observation == "render":
                self.frame_shape, self._scales = p.frame_shape, None
                self._make_rendering(ids)
            else:
                self.envs = [gymnasium.make(env_id, max_episode_steps=p.max_episode_steps) for env_id in ids]
                self._scales = [VectorScale(env.observation_space, p.observation_range, where=type(p).__name__,
                                            env=name) for env, name in zip(self.envs, p.envs)]
                sizes = {name: scale.size for name, scale in zip(p.envs, self._scales)}
                if len(set(sizes.values())) > 1:
                    raise ValueError(f"observation = 'vector' needs observations of one size in every environment; "
                                     f"got sizes {sizes}")
                self.frame_shape = (1, self._scales[0].size)
        except BaseException:
            self.close()
            raise
        n = self.n_contexts
        self._fixed_seeds = [s if s >= 0 else None for s in p.reset_seeds] if p.reset_seeds else [None] * n
        self._options = [dict(o) or None for o in p.reset_options] if p.reset_options else [None] * n
        self._first_seeds: list[int | None] = [None] * n
        self._observations: list = [None] * n
        self._steps = [0] * n
        self._ended = [True] * n

    def _make_rendering(self, ids: Sequence[str]) -> None:
        """Make the environments of ``ids`` with ``render_mode="rgb_array"`` (into :attr:`envs`)."""
        p = self.params
        for i, env_id in enumerate(ids):
            entry = gymnasium.spec(env_id).entry_point
            metadata = getattr(load_env_creator(entry) if isinstance(entry, str) else entry, "metadata", None)
            modes = metadata.get("render_modes", []) if isinstance(metadata, dict) else None  # none declared: none
            if isinstance(modes, (list, tuple)) and "rgb_array" not in modes:
                raise ConfigError(type(p).__name__, f"envs[{i}]", "an environment that renders rgb_array frames "
                                  f"(its render modes: {list(modes)}); for its observation vectors, "
                                  "observation = 'vector'", describe(p.envs[i]))
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # headless: pygame renders off screen, quietly
        if any(_draws_with_pygame(env_id) for env_id in ids):
            with extra("gym", "a gym world of gymnasium's own environments"):
                import pygame  # noqa: F401
        for env_id in ids:
            self.envs.append(gymnasium.make(env_id, render_mode="rgb_array", max_episode_steps=p.max_episode_steps))
        for name, env in zip(p.envs, self.envs):
            if env.render_mode != "rgb_array":
                raise ValueError(f"gymnasium environment {name!r} cannot render rgb_array frames")

    def close(self) -> None:
        """Close every environment."""
        for env in self.envs:
            env.close()

    def _reset(self) -> None:
        for c, env in enumerate(self.envs):
            first, action_seed = (int(s) for s in self.np_random.integers(2**63, size=2))
            env.action_space.seed(action_seed)
            self._first_seeds[c] = first
        n = self.n_contexts
        self._observations, self._steps, self._ended = [None] * n, [0] * n, [True] * n

    def _visit(self, context: int) -> Episode:
        env = self.envs[context]
        frames = np.empty((self.visit_length, self.n_pixels))
        states = np.empty(self.visit_length, dtype=np.int64)
        starts = [0]
        for t in range(self.visit_length):
            if self._ended[context]:
                seed = self._fixed_seeds[context]
                if seed is None:
                    seed, self._first_seeds[context] = self._first_seeds[context], None
                self._observations[context], _ = env.reset(seed=seed, options=self._options[context])
                self._steps[context], self._ended[context] = 0, False
                if t:
                    starts.append(t)
            else:
                action = self.policy(env, self._observations[context])
                self._observations[context], _, terminated, truncated, _ = env.step(action)
                self._steps[context] += 1
                self._ended[context] = terminated or truncated
            if self._scales is None:
                frames[t] = to_frame(env.render(), self.frame_shape)
            else:
                frames[t] = self._scales[context](self._observations[context])
            states[t] = min(self._steps[context], self.n_states - 1)
        return Episode(frames=frames, states=states, context=context, starts=np.array(starts, dtype=np.int64))
