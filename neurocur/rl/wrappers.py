"""Gymnasium wrappers that add a VTA model's dopamine to an environment's reward.

:class:`IntrinsicReward` wraps one environment, :class:`IntrinsicRewardVector` a
``gymnasium.vector`` environment. Each runs the observations through the circuit's sensory path
(:mod:`neurocur.rl.path`: EC's slow features and HPC's errors, or the context alone for count
novelty) and adds ``scale * decay**t * DA`` to the reward of step ``t``; the two parts are in
``info["intrinsic_reward"]`` and ``info["extrinsic_reward"]``. The model is any registered VTA
type, a third-party one from the ``neurocur.regions`` entry-point group included
(docs/rl.md). The spaces are the environment's.

Every observation is checked against the observation space
(:meth:`~neurocur.rl.observations.ObservationCoder.check`): a wrong shape or dtype or a value that
is not finite is a one-line ConfigError (a ValueError) naming the step of the episode and the
index; finite values outside the bounds are clipped in the frame and counted in
``info["observation_out_of_bounds"]``. The slow-feature regions' ``n_pca`` and ``n_components``
fit an observation's size unless ``overrides`` sets them, as IncSFA's own ``n_pca=None`` does.

The curiosity memory (the circuit's learned modules, the VTA's counts or previous errors) spans
the environment's episodes: it is built at the first reset and rebuilt, from the seed, at every
reset with a seed, so a run is reproduced by its seed (``reset(seed=s)``; ``SeedSequence(s)`` is
spawned into the observation coder's stream and the circuit's).
"""

from __future__ import annotations

from collections.abc import Mapping

import gymnasium as gym
import numpy as np
from gymnasium.error import ResetNeeded
from gymnasium.vector import AutoresetMode, VectorWrapper

from ..config import ConfigError
from .observations import ObservationCoder
from .path import COUNT_MODELS, SensoryPath, model_circuit

__all__ = ["IntrinsicReward", "IntrinsicRewardVector", "DEFAULT_FRAMES"]

#: Steps per pass by path when ``frames`` is not given (docs/rl.md, "Passes and blocks").
DEFAULT_FRAMES = {"counts": 1, "slow_features": 32}


class _Curiosity:
    """What both wrappers share: the model's circuit, checked once, and the sensory path built from a seed."""

    def __init__(self, space, *, model, scale, decay, params, circuit, inputs, overrides, path, frames, contexts,
                 bins, hash_bits, image_size, streams, source):
        for key, value, ok in (("scale", scale, True), ("decay", decay, 0.0 < _number(decay) <= 1.0)):
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value) and ok):
                raise ConfigError(source, key, "a finite number" + (" in (0, 1]" if key == "decay" else ""),
                                  repr(value))
        self.space, self.streams, self.source = space, streams, source
        self.scale, self.decay = float(scale), float(decay)
        self.circuit = model_circuit(model, params=params, circuit=circuit, inputs=inputs, source=source)
        if overrides:
            self.circuit = self.circuit.with_params(overrides, source=f"{source} overrides")
        self.path = path if path is not None else "counts" if model in COUNT_MODELS else "slow_features"
        self.frames = frames if frames is not None else DEFAULT_FRAMES.get(self.path, 1)
        self.coding = {"contexts": contexts, "bins": bins, "hash_bits": hash_bits, "image_size": image_size}
        n_values = ObservationCoder(space, rng=np.random.default_rng(0), source=source, **self.coding).n_pixels
        self.circuit = _fitted(self.circuit, n_values, dict(overrides or {}), source)
        self.build(np.random.SeedSequence(0))  # every argument is checked here, not at the first reset
        self.sensory = None

    def build(self, seed: np.random.SeedSequence) -> None:
        coder_seed, circuit_seed = seed.spawn(2)
        coder = ObservationCoder(self.space, rng=np.random.default_rng(coder_seed), source=self.source, **self.coding)
        self.sensory = SensoryPath(self.circuit, self.path, coder, frames=self.frames, seed=circuit_seed,
                                   streams=self.streams, source=self.source)
        self.weight = self.scale

    def reset(self, seed) -> None:
        if seed is not None or self.sensory is None:
            self.build(np.random.SeedSequence(seed))

    def bonus(self, da) -> float:
        """This step's bonus for the pass's ``da`` (None: no pass closed at this step)."""
        return 0.0 if da is None else self.weight * da

    def tick(self) -> None:
        self.weight *= self.decay


def _fitted(circuit, n_values: int, overrides: dict, source: str):
    """``circuit`` with the slow-feature regions' sizes fitted to a frame of ``n_values`` values, as
    IncSFA's own default does (``n_pca=None``: min(3, the input's values)): a region's ``n_pca``
    above ``n_values`` becomes None and its ``n_components`` at most ``n_values``, unless ``overrides``
    sets them, where a larger value is a ConfigError."""
    fitted = {}
    for name, spec in circuit.specs.items():
        if not (hasattr(spec.params, "n_pca") and hasattr(spec.params, "n_components")):
            continue
        n_pca, n_components = spec.params.n_pca, spec.params.n_components
        if n_pca is not None and n_pca > n_values:
            if f"{name}.n_pca" in overrides:
                raise ConfigError(f"{source} overrides", f"{name}.n_pca", f"at most the {n_values} values of an "
                                  f"observation's frame (or None: min(3, {n_values}))", repr(n_pca))
            fitted[f"{name}.n_pca"] = None
        if n_components > n_values:
            if f"{name}.n_components" in overrides:
                raise ConfigError(f"{source} overrides", f"{name}.n_components", f"at most the {n_values} values of "
                                  "an observation's frame", repr(n_components))
            fitted[f"{name}.n_components"] = n_values
    return circuit.with_params(fitted, source=source) if fitted else circuit


def _number(x) -> float:
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) else float("nan")


class IntrinsicReward(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """``env`` with the dopamine of VTA model ``model`` added to its reward.

    ``info`` of every step holds ``"intrinsic_reward"`` (the bonus) and ``"extrinsic_reward"`` (the
    environment's reward); the returned reward is their sum. ``"observation_out_of_bounds"`` (of
    every step and of the reset) is the number of the observation's values outside the observation
    space's bounds, clipped to them in its frame. An observation of another shape, of values that
    are not real numbers, or with a value that is not finite is a one-line ConfigError (a
    ValueError) naming the step of the episode (``reset`` for the reset's) and the index.

    Parameters
    ----------
    env : gymnasium.Env
        The environment; its observation space must be a vector Box or an image Box.
    model : str
        A VTA type (``"vta.learning_progress"``, ``"vta.novelty"``, ``"vta.surprise"``, ...; docs/regions.md), or
        a third-party one from the ``neurocur.regions`` entry points.
    scale, decay : float
        The bonus of step t is ``scale * decay**t * DA`` (t counts the steps since the memory was built).
    params : mapping, optional
        The model's parameters (``{"boredom": -1.0}``).
    circuit : Circuit or str or path, optional
        The circuit whose sensory path is used (a Circuit, a shipped circuit's name or a file; by default the
        shipped circuit of the model, else ``cd_misfa``).
    inputs : mapping of str to str, optional
        Edges into the model's extra inputs (``{"progress": "HPC.progress"}``).
    overrides : mapping, optional
        The circuit's parameters (``{"HPC.threshold": 0.5}``). EC's ``n_pca`` and ``n_components`` fit the
        values of an observation's frame (``n_pca`` 3 becomes None, min(3, values), as IncSFA's own default,
        and ``n_components`` at most the values) unless ``overrides`` sets them; an ``n_pca`` set above the
        values is an error.
    path : str, optional
        ``"slow_features"`` (EC and HPC) or ``"counts"`` (the VTA alone; the default for ``vta.novelty``).
    frames : int, optional
        Steps per pass (:data:`DEFAULT_FRAMES`).
    contexts : str, optional
        How observations become contexts (:class:`~neurocur.rl.observations.ObservationCoder`): ``"grid"``,
        ``"simhash"`` or ``None`` (grid for a vector Box with finite bounds, SimHash otherwise).
    bins : int
        Grid cells per dimension.
    hash_bits : int
        k of SimHash.
    image_size : int
        The largest side of an image frame.
    """

    def __init__(self, env: gym.Env, model: str = "vta.learning_progress", *, scale: float = 1.0,
                 decay: float = 1.0, params: Mapping | None = None, circuit=None, inputs: Mapping | None = None,
                 overrides: Mapping | None = None, path: str | None = None, frames: int | None = None,
                 contexts: str | None = None, bins: int = 8, hash_bits: int = 8, image_size: int = 16):
        options = {k: v for k, v in locals().items() if k not in ("self", "env", "__class__")}
        gym.utils.RecordConstructorArgs.__init__(self, **options)
        gym.Wrapper.__init__(self, env)
        self.curiosity = _Curiosity(env.observation_space, streams=1, source=type(self).__name__, **options)

    @property
    def sensory(self) -> SensoryPath | None:
        """The sensory path of the current memory (None before the first reset)."""
        return self.curiosity.sensory

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        self.curiosity.reset(seed)
        outside = self.curiosity.sensory.start(obs)
        return obs, {**info, "observation_out_of_bounds": outside}

    def step(self, action):
        if self.curiosity.sensory is None:
            raise ResetNeeded("IntrinsicReward: call reset() before step()")
        obs, reward, terminated, truncated, info = self.env.step(action)
        da, outside = self.curiosity.sensory.step(obs, reward)
        bonus = self.curiosity.bonus(da)
        self.curiosity.tick()
        return obs, float(reward) + bonus, terminated, truncated, {
            **info, "intrinsic_reward": bonus, "extrinsic_reward": float(reward), "observation_out_of_bounds": outside}


class IntrinsicRewardVector(VectorWrapper):
    """:class:`IntrinsicReward` for a ``gymnasium.vector`` environment (same arguments).

    The sub-environments share one curiosity memory (one circuit, as one agent's), each with its
    own block of steps; at every step they run through it in index order. Autoreset modes
    ``NEXT_STEP`` (gymnasium's default: the step after an episode's end only resets, and gets no
    bonus) and ``SAME_STEP`` (the last observation is ``info["final_obs"]``) are handled.
    ``info`` holds ``"intrinsic_reward"``, ``"extrinsic_reward"`` and
    ``"observation_out_of_bounds"`` as arrays, one entry per sub-environment (with ``SAME_STEP``, the
    last observation's count plus the reset's); ``decay`` applies once per step of the vector
    environment. An error names the sub-environment.

    Parameters
    ----------
    env : gymnasium.vector.VectorEnv
        The vector environment.
    model, scale, decay, params, circuit, inputs, overrides, path, frames, contexts, bins, hash_bits, image_size : object
        As :class:`IntrinsicReward` takes them.
    """

    def __init__(self, env: gym.vector.VectorEnv, model: str = "vta.learning_progress", *, scale: float = 1.0,
                 decay: float = 1.0, params: Mapping | None = None, circuit=None, inputs: Mapping | None = None,
                 overrides: Mapping | None = None, path: str | None = None, frames: int | None = None,
                 contexts: str | None = None, bins: int = 8, hash_bits: int = 8, image_size: int = 16):
        options = {k: v for k, v in locals().items() if k not in ("self", "env", "__class__")}
        super().__init__(env)
        source = type(self).__name__
        self.mode = env.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
        if self.mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise ConfigError(source, "autoreset_mode", "AutoresetMode.NEXT_STEP or SAME_STEP", str(self.mode))
        self.curiosity = _Curiosity(env.single_observation_space, streams=env.num_envs, source=source, **options)
        self._restart = np.zeros(env.num_envs, dtype=bool)

    @property
    def sensory(self) -> SensoryPath | None:
        """The sensory path of the current memory (None before the first reset)."""
        return self.curiosity.sensory

    def reset(self, *, seed=None, options: dict | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        self.curiosity.reset(seed[0] if isinstance(seed, (list, tuple)) else seed)
        outside = np.array([self.curiosity.sensory.start(obs[i], i) for i in range(self.num_envs)])
        self._restart[:] = False
        return obs, {**info, "observation_out_of_bounds": outside}

    def step(self, actions):
        if self.curiosity.sensory is None:
            raise ResetNeeded("IntrinsicRewardVector: call reset() before step()")
        obs, reward, terminated, truncated, info = self.env.step(actions)
        sensory, done = self.curiosity.sensory, terminated | truncated
        bonus, outside = np.zeros(self.num_envs), np.zeros(self.num_envs, dtype=np.int64)
        for i in range(self.num_envs):
            if self._restart[i]:  # NEXT_STEP: this step only reset sub-environment i
                outside[i] = sensory.start(obs[i], i)
                continue
            last = info["final_obs"][i] if self.mode == AutoresetMode.SAME_STEP and done[i] else obs[i]
            da, outside[i] = sensory.step(last, float(reward[i]), i)
            bonus[i] = self.curiosity.bonus(da)
            if self.mode == AutoresetMode.SAME_STEP and done[i]:
                outside[i] += sensory.start(obs[i], i)
        self._restart = done if self.mode == AutoresetMode.NEXT_STEP else self._restart
        self.curiosity.tick()
        extrinsic = np.asarray(reward, dtype=np.float64)
        return obs, extrinsic + bonus, terminated, truncated, {
            **info, "intrinsic_reward": bonus, "extrinsic_reward": extrinsic, "observation_out_of_bounds": outside}
