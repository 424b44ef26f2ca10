"""The context API: a multi-context sensory world with a gymnasium-like interface.

A *world* holds several contexts (paper section 2.2.1). Visiting a context yields an
:class:`Episode`: a block of frames (rows are time, columns are pixels) and the
context-state of each frame (the local time step in the synthetic world, the arm's
joint state on the iCub). The agent chooses which context to visit next; the world
never decides that.

    world.reset(seed=...)          -> (episode, info)     # first visit
    world.step(context)            -> (episode, 0.0, False, False, info)

There is no extrinsic reward, so the reward slot is always 0.0 and episodes never
terminate the world; the tuple keeps gymnasium's shape so that tooling built for it
reads naturally.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Episode:
    """One visit of a context.

    ``frames``: float64 (T, n_pixels), values in [0, 1].
    ``states``: int64 (T,), the context-state of each frame, in ``range(world.n_states)``.
    ``context``: index of the visited context.
    ``starts``: row indices where an independent episode begins inside this block
    (``[0]`` for one episode). A temporal derivative never spans a start.
    """

    frames: np.ndarray
    states: np.ndarray
    context: int
    starts: np.ndarray = field(default_factory=lambda: np.zeros(1, dtype=np.int64))

    def segments(self):
        """Yield ``(frames, states)`` for each independent episode in the block."""
        bounds = list(self.starts) + [len(self.frames)]
        for a, b in zip(bounds[:-1], bounds[1:]):
            yield self.frames[a:b], self.states[a:b]


class World(ABC):
    """Base class of multi-context worlds.

    Subclasses set ``context_names`` (tuple of str), ``source_names`` (one per
    context: which hidden driving force or object it shows), ``n_states`` and
    ``frame_shape``, and implement :meth:`_reset` and :meth:`_visit`.
    """

    context_names: tuple[str, ...]
    source_names: tuple[str, ...]
    n_states: int
    frame_shape: tuple[int, int]

    def __init__(self) -> None:
        self.np_random = np.random.default_rng()

    @property
    def n_contexts(self) -> int:
        return len(self.context_names)

    @property
    def n_pixels(self) -> int:
        return int(np.prod(self.frame_shape))

    def reset(self, *, seed=None, context: int = 0):
        """Start a new run (new mixing, clocks, ...) and return the first visit of ``context``."""
        self.np_random = np.random.default_rng(seed)
        self._reset()
        return self._visit(self._check_context(context)), {"context": context}

    def step(self, context: int):
        """Visit ``context`` and return ``(episode, 0.0, False, False, info)``."""
        ep = self._visit(self._check_context(context))
        return ep, 0.0, False, False, {"context": context}

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
