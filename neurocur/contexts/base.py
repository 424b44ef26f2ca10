"""The context API: a multi-context sensory world with gymnasium's reset/step semantics.

A *world* holds several contexts (paper section 2.2.1). Visiting a context yields an
:class:`Episode`: a block of frames (rows are time, columns are pixels) and the
context-state of each frame (the local time step in the synthetic world, the arm's
joint state on the iCub). The agent chooses which context to visit next; the world
never decides that.

    world.reset(seed=None, options=None)   -> (episode, info)     # a new run, first visit
    world.step(context)                    -> (episode, 0.0, False, False, info)
    world.visits(context, n)               -> episode: n visits of context as one block

Seeding follows gymnasium: ``reset(seed=s)`` re-seeds :attr:`World.np_random` with
``numpy.random.default_rng(s)``; ``reset()`` without a seed starts a new run from the
generator as it stands (seeded from the OS only if it never was). ``options`` may carry
``{"context": i}``, the context of the first visit (default 0; also the keyword
``context``). The reward of a step is the visit's extrinsic reward,
:attr:`Episode.reward`: 0.0 unless the world declares rewards per context (``rewards``,
:mod:`.rewards`), which :meth:`World.reset` and :meth:`World.step` pay into each episode.
Episodes never terminate the world. :meth:`World.as_env` wraps a world as a real
``gymnasium.Env`` (:class:`neurocur.contexts.env.WorldEnv`).

**The frame contract** (:func:`conform_frames`) is enforced by :meth:`World.reset`,
:meth:`World.step` and :meth:`World.visits`, where every episode leaves a world: frames are
float64 in [0, 1] (a world whose frames keep it by construction, :attr:`World.frames_conform`,
checks what it renders instead).
uint8 frames are divided by 255; frames of another numeric type are converted to float64
when their values lie in [0, 1] (up to :data:`FRAME_TOLERANCE`, values kept as they are);
any other frames are a ``ValueError`` naming the world, the context and the range found.
One pass over the frames per episode.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numba import njit

from ..registry import Registry
from .env import WorldEnv
from .rewards import Rewards

__all__ = ["FRAME_TOLERANCE", "WORLDS", "Episode", "SourceSpec", "World", "concatenate_episodes", "conform_frames",
           "register_world"]

#: World types by name; third-party world types come from the entry-point group ``neurocur.worlds``.
WORLDS = Registry("world", "neurocur.worlds")
#: Class decorator: ``@register_world("synthetic")``.
register_world = WORLDS.register


@dataclass(frozen=True)
class Episode:
    """One visit of a context.

    Parameters
    ----------
    frames : array of float64, shape (T, n_pixels)
        Values in [0, 1]; :meth:`World.reset` and :meth:`World.step` enforce it (:func:`conform_frames`).
    states : array of int64, shape (T,)
        The context-state of each frame, in ``range(world.n_states)``.
    context : int
        Index of the visited context.
    starts : array of int64
        Row indices where an independent episode begins inside this block (``[0]`` for one episode).
        A temporal derivative never spans a start.
    reward : float
        The extrinsic reward the world pays for this visit (0 unless the experiment declares one for
        the context).
    """

    frames: np.ndarray
    states: np.ndarray
    context: int
    starts: np.ndarray = field(default_factory=lambda: np.zeros(1, dtype=np.int64))
    reward: float = 0.0

    def segments(self):
        """Yield ``(frames, states)`` for each independent episode in the block."""
        bounds = list(self.starts) + [len(self.frames)]
        for a, b in zip(bounds[:-1], bounds[1:]):
            yield self.frames[a:b], self.states[a:b]

    def derivative(self, y: np.ndarray) -> np.ndarray:
        """The temporal derivative of per-frame values ``y`` (rows are this block's frames):
        ``y[t] - y[t-1]``, NaN at every start (row 0 included), so that none spans two
        independent episodes."""
        dy = np.empty_like(y)
        dy[0] = np.nan
        dy[1:] = np.diff(y, axis=0)
        dy[self.starts] = np.nan
        return dy


def concatenate_episodes(episodes) -> Episode:
    """One block from consecutive episodes of a context; ``starts`` marks every segment, ``reward`` is their sum.

    Parameters
    ----------
    episodes : sequence of Episode
        Consecutive episodes of one context.

    Returns
    -------
    Episode
        The block.
    """
    offsets = np.cumsum([0] + [len(e.frames) for e in episodes[:-1]])
    return Episode(
        frames=np.concatenate([e.frames for e in episodes]),
        states=np.concatenate([e.states for e in episodes]),
        context=episodes[0].context,
        starts=np.concatenate([e.starts + o for e, o in zip(episodes, offsets)]).astype(np.int64),
        reward=float(sum(e.reward for e in episodes)),
    )


#: How far beyond [0, 1] a frame value may lie (floating-point rounding of a normalisation).
FRAME_TOLERANCE = 1e-9


@njit(cache=True, nogil=True)
def _in_unit_range(flat, tol):  # pragma: no cover - compiled
    """True when every value is in [-tol, 1 + tol] (NaN is not); stops after the first block with one
    outside. Inside a block the test is branch-free, so the loop is vectorised."""
    low, high = -tol, 1.0 + tol
    n = flat.shape[0]
    for a in range(0, n, 1024):
        ok = True
        for i in range(a, min(a + 1024, n)):
            v = flat[i]
            ok &= (v >= low) & (v <= high)
        if not ok:
            return False
    return True


def conform_frames(episode: Episode, world=None) -> Episode:
    """``episode`` with frames that keep the contract: float64 in [0, 1] (see the module docstring).

    float64 frames in range come back as the same object, untouched; uint8 frames are
    divided by 255; other integer, boolean or float frames in range are converted to
    float64. Frames outside [0, 1] (beyond :data:`FRAME_TOLERANCE`), with NaN, or of a
    non-numeric type raise ``ValueError`` naming ``world``, the context and the range found.

    Parameters
    ----------
    episode : Episode
        The episode a world delivered.
    world : object
        The world, named in the message.

    Returns
    -------
    Episode
        ``episode``, or a copy with float64 frames.
    """
    frames = np.asarray(episode.frames)
    if frames.dtype == np.uint8:
        return dataclasses.replace(episode, frames=frames / 255.0)
    if frames.dtype.kind not in "biuf":
        raise ValueError(f"{_where(world, episode.context)}: frames must be float64 in [0, 1] "
                         f"(or uint8, divided by 255); got frames of dtype {frames.dtype}")
    dtype = frames.dtype
    if dtype.kind == "b" or dtype.itemsize < 4:  # bool, 8/16-bit types: a float64 copy to check
        frames = frames.astype(np.float64)
    if frames.size and not _in_unit_range(frames.reshape(-1), FRAME_TOLERANCE):
        _out_of_range(frames, dtype, world, episode.context)
    if frames is episode.frames and frames.dtype == np.float64:
        return episode
    return dataclasses.replace(episode, frames=frames.astype(np.float64, copy=False))


def _where(world, context) -> str:
    if world is None:
        return f"context {context}"
    names = getattr(world, "context_names", ())
    name = f" {names[context]!r}" if isinstance(context, (int, np.integer)) and 0 <= context < len(names) else ""
    return f"world {type(world).__name__}, context{name} (index {context})"


def _out_of_range(frames, dtype, world, context):
    finite = frames[np.isfinite(frames)] if frames.dtype.kind == "f" else frames
    found = f"[{finite.min()}, {finite.max()}]" if finite.size else "no finite value"
    nan = int(np.isnan(frames).sum()) if frames.dtype.kind == "f" else 0
    extra = f" and {nan} NaN value(s)" if nan else ""
    raise ValueError(f"{_where(world, context)}: frames must be float64 in [0, 1] (uint8 frames are divided by 255); "
                     f"found {dtype} values in {found}{extra}")


@dataclass(frozen=True)
class SourceSpec:
    """Which source drives each context, and the learnable sources in Ω order.

    Every other source of the world is unlearnable (noise).

    Parameters
    ----------
    context_names : tuple of str
        ``context_names[i]`` names context index ``i``.
    context_sources : tuple of str
        ``context_sources[i]`` is the source that drives context index ``i``.
    learnable : tuple of str
        The learnable sources, easiest first (ascending Ω, eq 15).
    """

    context_names: tuple[str, ...]
    context_sources: tuple[str, ...]
    learnable: tuple[str, ...]

    def __post_init__(self):
        if len(self.context_names) != len(self.context_sources):
            raise ValueError(
                f"SourceSpec expected one source per context, got {len(self.context_names)} "
                f"names and {len(self.context_sources)} sources"
            )
        unknown = set(self.learnable) - set(self.context_sources)
        if unknown:
            raise ValueError(f"SourceSpec: learnable sources {sorted(unknown)} drive no context")

    @property
    def unlearnable(self) -> tuple[str, ...]:
        return tuple(s for s in dict.fromkeys(self.context_sources) if s not in self.learnable)

    def contexts_of(self, source: str) -> list[int]:
        """Indices of the contexts driven by ``source``."""
        return [i for i, s in enumerate(self.context_sources) if s == source]

    def source_of_name(self, name: str) -> str | None:
        """The source of the context called ``name`` (None if there is none)."""
        return dict(zip(self.context_names, self.context_sources)).get(name)


class World(ABC):
    """Base class of multi-context worlds.

    Subclasses set ``context_names`` (tuple of str), ``source_names`` (one per
    context: which hidden driving force or object it shows), ``n_states``,
    ``frame_shape`` and, if their visits have a longest length, ``max_frames``, and
    implement :meth:`_reset` (drawing from :attr:`np_random`) and :meth:`_visit`.
    """

    context_names: tuple[str, ...]
    source_names: tuple[str, ...]
    n_states: int
    frame_shape: tuple[int, int]
    #: The most frames one visit returns (the padded length of :meth:`as_env`'s observation);
    #: None if the world does not bound it.
    max_frames: int | None = None
    #: True when every frame the world's visits return is float64 in [0, 1] by construction (the
    #: world checks what it renders, once): :meth:`reset`, :meth:`step` and :meth:`visits` then
    #: skip :func:`conform_frames`, a pass over every episode's frames.
    frames_conform: ClassVar[bool] = False
    #: True for a small task whose experiments are read through their figures (the canonical tasks of
    #: docs/validation.md): ``neurocur run`` then draws the folder's figures after its runs, as
    #: ``neurocur figures`` would.
    figures_after_run: ClassVar[bool] = False
    #: The extrinsic reward of each visit (:mod:`.rewards`); None pays 0.0. Subclasses set it
    #: from their parameters' ``rewards`` (``Rewards.of(params.rewards)``).
    rewards: Rewards | None = None
    _np_random: np.random.Generator | None = None

    @property
    def n_contexts(self) -> int:
        return len(self.context_names)

    @property
    def n_pixels(self) -> int:
        return int(np.prod(self.frame_shape))

    @property
    def np_random(self) -> np.random.Generator:
        """The world's generator: set by ``reset(seed=...)``, seeded from the OS on first use if never seeded."""
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    @np_random.setter
    def np_random(self, value: np.random.Generator) -> None:
        self._np_random = value

    def reset(self, *, seed=None, options: dict | None = None, context: int | None = None):
        """Start a new run (new mixing, clocks, ...) and return ``(first visit, info)``.

        ``seed`` re-seeds :attr:`np_random` (``numpy.random.default_rng(seed)``); without
        one the run is drawn from the generator's current stream. The first visit is of
        ``options["context"]`` or ``context`` (default 0); ``options`` has no other key.
        """
        options = dict(options or {})
        unknown = set(options) - {"context"}
        if unknown:
            raise ValueError(f"reset options may only hold 'context'; got {sorted(unknown)}")
        if context is not None and "context" in options:
            raise ValueError("give the first context either as options['context'] or as context=, not both")
        context = self._check_context(options.get("context", 0 if context is None else context))
        if seed is not None:
            self._np_random = np.random.default_rng(seed)
        self._reset()
        if self.rewards is not None:
            self.rewards.reset()
        return self._paid(self._conformed(self._visit(context))), {"context": context}

    def step(self, context: int):
        """Visit ``context`` and return ``(episode, episode.reward, False, False, info)``."""
        ep = self._paid(self._conformed(self._visit(self._check_context(context))))
        return ep, ep.reward, False, False, {"context": context}

    def visits(self, context: int, n: int) -> Episode:
        """``n`` consecutive visits of ``context`` as one block (what staying in a context delivers).

        The same frames, states and random draws as ``n`` calls of :meth:`step`; ``starts``
        marks where each visit begins (a temporal derivative never spans two visits) and
        ``reward`` is the sum of the visits' rewards.
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"n must be a positive integer (visits); got {n!r}")
        return self._paid(self._conformed(self._visits(self._check_context(context), int(n))), int(n))

    def _visits(self, context: int, n: int) -> Episode:
        """The block of :meth:`visits`, unpaid, frames not yet conformed. Default: ``n`` :meth:`_visit`
        episodes joined; a world that can cut the block from its frames at once overrides it."""
        return concatenate_episodes([self._visit(context) for _ in range(n)])

    def _conformed(self, episode: Episode) -> Episode:
        """``episode`` with frames that keep the contract (:func:`conform_frames`; as it is when
        :attr:`frames_conform`)."""
        return episode if self.frames_conform else conform_frames(episode, self)

    def _paid(self, episode: Episode, n: int = 1) -> Episode:
        """``episode`` with the extrinsic reward of the ``n`` visits it holds, their sum (unchanged when
        the world pays none)."""
        if self.rewards is None:
            return episode
        reward = self.rewards.pay(episode.context)
        for _ in range(n - 1):
            reward += self.rewards.pay(episode.context)
        return dataclasses.replace(episode, reward=float(reward))

    #: The parameter dataclass (fields made with :func:`neurocur.config.param`) that an
    #: experiment file's ``[world]`` table becomes; None for a world built only from Python.
    Params: ClassVar[type | None] = None

    @classmethod
    def pays_reward(cls, params) -> bool:
        """Whether a run of this world with ``params`` can pay a nonzero extrinsic reward (what a VTA that
        reads it needs; :func:`neurocur.experiments.build` refuses such a VTA in a world that pays none).
        Here: the ``rewards`` table (:mod:`.rewards`) has a nonzero entry; a world whose parameters have
        no ``rewards`` pays by its own rules and is taken to pay unless it overrides this."""
        if not hasattr(params, "rewards"):
            return True
        return any(v != 0 for entry in params.rewards or () for v in (entry if isinstance(entry, tuple) else (entry,)))

    @classmethod
    def from_params(cls, params) -> World:
        """The world of a :attr:`Params` instance: ``cls(params=params)`` (a world built otherwise overrides it)."""
        if cls.Params is None:
            raise NotImplementedError(f"{cls.__name__} has no parameter class: build it from Python")
        return cls(params=params)

    def as_env(self, *, max_frames: int | None = None, render_mode: str | None = "rgb_array"):
        """This world as a ``gymnasium.Env`` (:class:`neurocur.contexts.env.WorldEnv`): the action is
        the context to visit, the observation the visit padded to ``max_frames`` (default
        :attr:`max_frames`) rows. The env shares this world and its generator."""
        return WorldEnv(self, max_frames=max_frames, render_mode=render_mode)

    def close(self) -> None:
        """Release what the world holds open (e.g. simulators). Default: nothing to release."""
        return None

    @classmethod
    def prepare(cls, params) -> None:
        """Make the world of ``params`` cheap to build in every run (e.g. simulate a data set into
        its cache). Called once, before worker processes start. Default: nothing to do."""
        return None

    def source_spec(self) -> SourceSpec:
        """Which source each context shows, and the learnable sources in Ω order.

        The default: every source is learnable, in order of first appearance.
        """
        return SourceSpec(tuple(self.context_names), tuple(self.source_names), tuple(dict.fromkeys(self.source_names)))

    def module_report(self, library, modules) -> tuple[list, list, dict, dict]:
        """What each stored module learned, judged against this run's hidden sources.

        Called once at the end of a run, while the world still holds the run's sources.
        ``library``: the frozen modules (objects with ``transform``), ``modules``: the
        stored-module table (:data:`neurocur.contract.MODULE_COLUMNS`). Returns
        ``(sources, quality, columns, tables)``: per module the source of the context it
        was learned in and a quality in [0, 1] (NaN when the world has no ground truth,
        as here), further per-module columns by name, and further per-run tables by name.
        """
        sources = [self.source_names[int(c)] for c in modules["context"]]
        return sources, [float("nan")] * len(sources), {}, {}

    def _check_context(self, context) -> int:
        if not (isinstance(context, (int, np.integer)) and 0 <= context < self.n_contexts):
            raise ValueError(f"context must be an int in [0, {self.n_contexts}); got {context!r}")
        return int(context)

    @abstractmethod
    def _reset(self) -> None:
        """Draw everything that is random per run from ``self.np_random``."""

    @abstractmethod
    def _visit(self, context: int) -> Episode:
        """Return the next episode of ``context`` and advance its local clock."""
