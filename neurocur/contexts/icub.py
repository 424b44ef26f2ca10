"""The simulated iCub world (paper section 4.2): two object contexts seen by a fixed eye.

The robot's head is fixed; its eye camera gives grayscale 75×100 frames. The right
arm babbles with a single shoulder joint over 20 quantized states (the context-state):
each frame the joint moves to an adjacent state (a ±1 random walk, reflecting at the
ends), so the outstretched hand eventually hits the single object on the table:

- ``"topple"``: a cup that the hand tips over, much the same way every time;
- ``"roll"``: a ball that the fingertip strikes glancingly, so it rolls off in a
  direction that differs from episode to episode (its placement along the arm's radius
  is drawn per episode within ``±ball_jitter``; see :mod:`.icub_scene`).

An episode starts with the arm at ``start_state`` and the object in its place; it
ends ``post_contact`` frames after the first hand–object contact, never before
``min_frames`` and at most at ``max_frames`` frames (50–250 in the paper).

Episodes are simulated with MuJoCo and rendered once, and cached on disk
(:mod:`.icub_data`); a run (:meth:`World.reset`) then draws episodes from that pool in a
per-run random order.

Learning difficulty: :func:`omega_episodes` is Ω (eq 15/40) of a list of episodes with
the derivative taken within episodes only, after a PCA keeping 98 % of the variance
(the paper's 0.9982 for topple and 0.9988 for the rolling ball).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import ConfigError, ParamSpec, check_params, describe, param, spec_param
from ..config.checks import check_fraction
from ..learn.correlation import abs_corr
from ..learn.omega import omega
from .base import Episode, SourceSpec, World, register_world
from .icub_data import (
    FRAME_SHAPE,
    EpisodeParams,
    EpisodePool,
    _generate,
    blurred,
    cache_key,
    cached,
    default_cache_dir,
)
from .icub_scene import OBJECTS, SceneParams
from .rewards import Rewards, check_rewards, rewards_param

#: The iCub world's contexts: each shows its own object, both learnable, in Ω order
#: (topple easier: the paper's Ω 0.9982 < 0.9988; measured in docs/icub.md).
ICUB = SourceSpec(context_names=OBJECTS, context_sources=OBJECTS, learnable=OBJECTS)
#: reference episodes (pool indices, both contexts) whose slow-feature outputs each run stores
REFERENCE_EPISODES = (0, 1, 2)


@dataclass(frozen=True)
class ICubParams:
    """Parameters of :class:`ICubWorld` (an experiment file's ``[world]`` table, ``type = "icub"``)."""

    n_episodes: int = param(70, int, low=1, doc="episodes per context in the data set")
    dataset_seed: int = param(0, int, low=0, doc="seed of the simulated data set (not of the runs)")
    cache_dir: str | None = spec_param(None, ParamSpec(str, optional=True, path=True, classes=(os.PathLike,)),
                                       doc="default $NEUROCUR_CACHE/icub or ~/.cache/neurocur/icub")
    n_jobs: int = param(2, int, low=1, doc="processes that simulate the data set")
    scene: SceneParams = spec_param(SceneParams(), ParamSpec.nested(SceneParams), doc="geometry and physics")
    protocol: EpisodeParams = spec_param(EpisodeParams(), ParamSpec.nested(EpisodeParams), doc="episode protocol")
    rewards: tuple | None = rewards_param()
    blur: float = param(0.0, float, low=0.0, doc="standard deviation (pixels) of a Gaussian blur of every frame, "
                        "as by a camera's optics; 0 = none (the blurred data set is cached beside the sharp one)")

    def __post_init__(self):
        check_params(self)
        check_rewards(self, len(OBJECTS), OBJECTS)
        if self.protocol.start_state >= self.scene.n_states:
            raise ConfigError(type(self).__name__, "protocol.start_state", f"< scene.n_states = {self.scene.n_states}",
                              describe(self.protocol.start_state))


@register_world("icub")
class ICubWorld(World):
    """Two object contexts, ``"topple"`` (cup) and ``"roll"`` (ball), seen by the iCub's eye.

    ``n_episodes`` episodes per context are simulated once from ``seed`` and cached under
    ``cache_dir`` (default :func:`default_cache_dir`); a later construction with the same
    parameters reads the cache. :meth:`reset` draws a per-run random order of each
    context's pool, and :meth:`step` returns that context's next episode (a fresh order
    is drawn each time a context's pool is used up). The context-state is the shoulder
    joint's state (0..19). ``last_info`` (also merged into the ``info`` dicts) names the
    pool index and the contact frame of the episode just returned. ``rewards``: extrinsic
    reward per context, topple then roll (:mod:`.rewards`).
    """

    Params = ICubParams
    context_names = OBJECTS
    source_names = OBJECTS
    frame_shape = FRAME_SHAPE
    #: Frames are the cached 8-bit gray values divided by 255: float64 in [0, 1] by construction.
    frames_conform = True

    def __init__(
        self,
        n_episodes: int = 70,
        seed: int = 0,
        cache_dir=None,
        *,
        scene: SceneParams | None = None,
        protocol: EpisodeParams | None = None,
        n_jobs: int = 2,
        rewards=None,
        params: ICubParams | None = None,
    ) -> None:
        super().__init__()
        if params is None:
            params = ICubParams(n_episodes=n_episodes, dataset_seed=seed, cache_dir=cache_dir, n_jobs=n_jobs,
                                scene=scene or SceneParams(), protocol=protocol or EpisodeParams(), rewards=rewards)
        self.params = params
        self.rewards = Rewards.of(params.rewards)
        self.n_episodes, self.seed = params.n_episodes, params.dataset_seed
        self.scene, self.protocol = params.scene, params.protocol
        self.n_states = self.scene.n_states
        self.max_frames = self.protocol.max_frames
        sharp = cache_file(params, blurred=False)

        def simulated():
            return cached(sharp, lambda: _generate(self.scene, self.protocol, self.n_episodes, self.seed, params.n_jobs))

        self.cache_path = cache_file(params)
        if params.blur > 0:
            self.pools = cached(self.cache_path, lambda: blurred(simulated(), params.blur))
        else:
            self.pools = simulated()
        self.last_info: dict = {}
        self._reset()

    @classmethod
    def prepare(cls, params: ICubParams) -> None:
        """Simulate the episode data set into its cache (constructing the world does that)."""
        cls.from_params(params)

    def reset(self, *, seed=None, options: dict | None = None, context: int | None = None):
        ep, info = super().reset(seed=seed, options=options, context=context)
        return ep, {**info, **self.last_info}

    def step(self, context: int):
        ep, reward, terminated, truncated, info = super().step(context)
        return ep, reward, terminated, truncated, {**info, **self.last_info}

    def _reset(self) -> None:
        self._order = [np.empty(0, dtype=np.int64) for _ in OBJECTS]
        self._cursor = [0] * len(OBJECTS)

    def _next_index(self, context: int) -> int:
        """The pool index of the next visit of ``context`` (a fresh random order of the pool each
        time it is used up); :attr:`last_info` describes that visit."""
        if self._cursor[context] >= len(self._order[context]):
            self._order[context] = self.np_random.permutation(self.n_episodes)
            self._cursor[context] = 0
        index = int(self._order[context][self._cursor[context]])
        self._cursor[context] += 1
        self.last_info = {
            "context": context,
            "episode_index": index,
            "contact_frame": self.contact_frame(context, index),
        }
        return index

    def _visit(self, context: int) -> Episode:
        return self._cut(context, [self._next_index(context)])

    def _visits(self, context: int, n: int) -> Episode:
        return self._cut(context, [self._next_index(context) for _ in range(n)])

    def _cut(self, context: int, indices) -> Episode:
        """The pool episodes ``indices`` of ``context`` as one unpaid block: their 8-bit rows joined,
        then scaled to float64 once (one pass over float64 frames, not one per episode and a join)."""
        pool = self.pools[OBJECTS[context]]
        rows = [pool.rows(i) for i in indices]
        lengths = [r.stop - r.start for r in rows]
        return Episode(
            frames=np.concatenate([pool.frames[r] for r in rows]).reshape(-1, self.n_pixels) / 255.0,
            states=np.concatenate([pool.states[r] for r in rows]),
            context=int(context),
            starts=np.cumsum([0] + lengths[:-1]).astype(np.int64),
        )

    def _pool(self, context, index) -> tuple[EpisodePool, slice]:
        context = self._check_context(context)
        if not (isinstance(index, (int, np.integer)) and 0 <= index < self.n_episodes):
            raise ValueError(f"episode_index must be an int in [0, {self.n_episodes}); got {index!r}")
        pool = self.pools[OBJECTS[context]]
        return pool, pool.rows(int(index))

    def episode(self, context: int, episode_index: int) -> Episode:
        """Episode ``episode_index`` of the cached pool of ``context`` (frames as float64 in [0, 1])."""
        self._pool(context, episode_index)  # a ValueError for a bad context or index
        return self._cut(int(context), [int(episode_index)])

    def object_positions(self, context: int, episode_index: int) -> np.ndarray:
        """Ground truth: the object's centre (x, y, z) in metres at each frame, (T, 3)."""
        pool, rows = self._pool(context, episode_index)
        return pool.positions[rows].copy()

    def displacement(self, context: int, episode_index: int) -> np.ndarray:
        """Ground truth: distance (m) of the object's centre from its start, per frame, (T,)."""
        pos = self.object_positions(context, episode_index)
        return np.linalg.norm(pos - pos[0], axis=1)

    def contact_frame(self, context: int, episode_index: int) -> int:
        """Frame of the first hand–object contact, or -1 if the hand never touched the object."""
        pool, _ = self._pool(context, episode_index)
        return int(pool.contact[episode_index])

    def episodes(self, context: int) -> list[Episode]:
        """Every cached episode of ``context``, in pool order."""
        return [self.episode(context, i) for i in range(self.n_episodes)]

    def module_report(self, library, modules):
        """What each stored module's slowest output y₀ encodes, over every cached episode.

        Returns ``(sources, quality, columns, tables)``. Per module (a row of ``modules``,
        learned in context ``c``), all on the pooled frames of every episode of a context:

        - ``quality``: |corr(y₀, displacement)| on context ``c`` (the object's distance from
          its start, ``self.displacement``: "object displaced or not", section 4.2.2);
        - ``arm_corr``: |corr(y₀, arm joint state)| on context ``c`` (invariance to the arm);
        - ``other_quality``: |corr(y₀, displacement)| on the other context;
        - ``context_corr``: |corr(y₀, context index)| on both contexts (section 4.2.1: a module
          learned across both contexts codes for the context).

        ``tables["features"]``: every module's outputs on the reference episodes
        ``REFERENCE_EPISODES`` of both contexts, one row per (module, frame): module,
        context, episode_index, frame, state, displacement, contact_frame, y0, y1, ...
        """
        n_modules = len(modules)
        J = library[0].n_components if library else 0
        columns = ["module", "context", "episode_index", "frame", "state", "displacement", "contact_frame",
                   *(f"y{j}" for j in range(J))]
        extra = {"arm_corr": [], "other_quality": [], "context_corr": []}
        if not library:
            return [], [], extra, {"features": pd.DataFrame(columns=columns)}
        proj = np.concatenate([m.projection_ for m in library], axis=1)
        offset = np.concatenate([m.mean_ @ m.projection_ for m in library])
        outputs, displacement, states, contexts, reference = [], [], [], [], []
        for c in range(self.n_contexts):
            for i in range(self.n_episodes):
                ep = self.episode(c, i)
                y = (ep.frames @ proj - offset).reshape(len(ep.frames), n_modules, J)
                d = self.displacement(c, i)
                outputs.append(y)
                displacement.append(d)
                states.append(ep.states)
                contexts.append(np.full(len(d), c))
                if i in REFERENCE_EPISODES:
                    frame = np.arange(len(d))
                    for m in range(n_modules):
                        reference.append(pd.DataFrame({
                            "module": m, "context": c, "episode_index": i, "frame": frame, "state": ep.states,
                            "displacement": d, "contact_frame": self.contact_frame(c, i),
                            **{f"y{j}": y[:, m, j] for j in range(J)}}))
        features = pd.concat(reference, ignore_index=True)[columns]
        context_of = np.concatenate(contexts)
        y0 = np.concatenate(outputs)[:, :, 0]
        displacement, states = np.concatenate(displacement), np.concatenate(states)
        sources, quality = [], []
        for row in modules.itertuples(index=False):
            m, c = int(row.module), int(row.context)
            own, other = context_of == c, context_of != c
            sources.append(self.source_names[c])
            quality.append(abs_corr(y0[own, m], displacement[own]))
            extra["arm_corr"].append(abs_corr(y0[own, m], states[own]))
            extra["other_quality"].append(abs_corr(y0[other, m], displacement[other]))
            extra["context_corr"].append(abs_corr(y0[:, m], context_of.astype(np.float64)))
        return sources, quality, extra, {"features": features}


def cache_file(params: ICubParams, *, blurred: bool = True) -> Path:
    """The file that caches the episode data set of ``params``: ``icub-<key>.npz`` in
    ``params.cache_dir`` (default :func:`~neurocur.contexts.icub_data.default_cache_dir`), the key
    hashing the scene, the protocol, the number of episodes and the seed; with a blur (and
    ``blurred``), its blurred copy ``icub-<key>-blur<sigma>.npz`` beside it."""
    key = cache_key(params.scene, params.protocol, params.n_episodes, params.dataset_seed)
    folder = Path(params.cache_dir or default_cache_dir()).expanduser()
    return folder / (f"icub-{key}-blur{params.blur:g}.npz" if blurred and params.blur > 0 else f"icub-{key}.npz")


def _principal_basis(U: np.ndarray, var_fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Leading principal directions of centred ``U`` that keep ``var_fraction`` of its variance.

    Randomized subspace iteration (Halko, Martinsson & Tropp 2011), doubling the sketch
    until the kept eigenvalues reach the fraction of the exact total variance ``‖U‖²``.
    """
    total = np.einsum("ij,ij->", U, U)
    k = 64
    while True:
        k = min(k, *U.shape)
        Q = np.linalg.qr(U.T @ (U @ rng.standard_normal((U.shape[1], k + 10))))[0]
        for _ in range(3):
            Q = np.linalg.qr(U.T @ (U @ Q))[0]
        _, sv, Vt = np.linalg.svd(U @ Q, full_matrices=False)
        frac = np.cumsum(sv**2) / total
        if frac[-1] >= var_fraction or k == min(U.shape):
            n = int(np.searchsorted(frac, var_fraction) + 1)
            return Q @ Vt[:n].T
        k *= 2


def pca_reduce(episodes, var_fraction: float = 0.98) -> list[np.ndarray]:
    """Project every episode onto the principal directions of all their frames together.

    The frames of all episodes (each an :class:`Episode` or a (T, D) array) are centred
    together and reduced to the leading directions that keep ``var_fraction`` of the
    variance (as CCIPCA does in section 4.2.1). Returns one (T, n) block per episode.
    """
    var_fraction = check_fraction(var_fraction, "var_fraction", source="pca_reduce")
    blocks = [np.asarray(e.frames if isinstance(e, Episode) else e, dtype=np.float64) for e in episodes]
    if not blocks or any(b.ndim != 2 or len(b) < 2 for b in blocks):
        raise ValueError("episodes must be a non-empty list of (T, D) blocks with T >= 2")
    X = np.concatenate(blocks)
    U = X - X.mean(axis=0)
    Y = U @ _principal_basis(U, var_fraction, np.random.default_rng(0))
    return np.split(Y, np.cumsum([len(b) for b in blocks])[:-1])


def omega_episodes(episodes, eta: float = 0.01, *, var_fraction: float = 0.98, rank_tol: float = 1e-10) -> float:
    """Ω (eqs 15, 40) of a set of episodes, the derivative taken within episodes only: the Ω of
    :func:`omega_and_dims`."""
    return omega_and_dims(episodes, eta, var_fraction=var_fraction, rank_tol=rank_tol)[0]


def omega_and_dims(episodes, eta: float = 0.01, *, var_fraction: float = 0.98,
                   rank_tol: float = 1e-10) -> tuple[float, int]:
    """Ω (eqs 15, 40) of a set of episodes and the PCA dimensions it was measured in.

    The episodes are reduced by :func:`pca_reduce` to the dimensions that keep ``var_fraction``
    of the variance (the paper's 98 %: "typically between 10 and 15", section 4.2.1), then
    :func:`~neurocur.learn.omega.omega` whitens them together and differences inside each episode.
    """
    reduced = pca_reduce(episodes, var_fraction)
    starts = np.cumsum([0] + [len(r) for r in reduced[:-1]])
    return omega(np.concatenate(reduced), eta, rank_tol=rank_tol, starts=starts), reduced[0].shape[1]
