"""The sensory world as a region: the context the agent is in, delivered one episode per pass."""

from __future__ import annotations

from dataclasses import dataclass

from ..config import check_params, param
from ..contexts.base import World, concatenate_episodes
from .base import Probe, Region, Signal, register


@dataclass(frozen=True)
class SensoryParams:
    episodes_on_engage: int = param(1, int, low=1, doc="episodes delivered when the agent stays (2 on the iCub)")
    initial_context: int = param(-1, int, low=-1, doc="context of the first episode; -1 draws it uniformly")

    def __post_init__(self):
        check_params(self)


@register("sensory.world")
class SensoryWorld(Region):
    """Wraps a :class:`~neurocur.contexts.base.World` (section 2.2.1).

    Step: visit the context chosen by LC at the end of the previous pass (a delayed
    input; ``None`` on the first pass, which returns the world's first episode). When
    the agent stayed (``next_context`` equals the current context) and
    ``episodes_on_engage`` > 1, the world delivers that many visits as one block whose
    ``starts`` mark the independent segments (:meth:`~neurocur.contexts.base.World.visits`;
    iCub experiment, section 4.2). ``reward`` is the extrinsic reward the world paid for
    the visit (``Episode.reward``; the sum over the visits of a block), 0 unless the
    experiment declares one.

    Reset starts the world's run from the world's own generator (``world.np_random``), which
    the simulator seeds under the world's own key (:func:`neurocur.scheduler.world_seed`): the
    world does not depend on this region's name or stream. The region's generator draws only
    the first context (when ``initial_context`` is -1).
    """

    Params = SensoryParams
    is_clock = True
    inputs = (Signal("next_context", "int64", (), "context chosen by LC at the previous pass"),)
    outputs = (
        Signal("episode", "Episode", (), "frames (T, n_pixels) in [0, 1], context-states (T,), segment starts"),
        Signal("context", "int64", (), "index of the context of this episode"),
        Signal("reward", "float64", (), "extrinsic reward the world paid for this episode", optional=True),
    )
    probes = (
        Probe("context", "int", "index", "context of this episode"),
        Probe("n_frames", "int", "frames", "frames in this episode (block)"),
        Probe("reward", "float", "reward units", "extrinsic reward the world paid for this episode (block)"),
    )
    frame_probes = (Probe("state", "int", "index", "context-state (local time step) of each frame"),)

    def bind(self, world) -> None:
        if world.n_contexts < 1:
            raise ValueError("the world has no context")
        if self.params.initial_context >= world.n_contexts:
            raise ValueError(f"{self.name}: initial_context must be < {world.n_contexts} (the world's contexts); "
                             f"got {self.params.initial_context}")
        self.world = world

    def reset(self, rng) -> None:
        c0 = self.params.initial_context
        if c0 < 0:
            c0 = int(rng.integers(self.world.n_contexts))
        self._first, _ = self.world.reset(seed=None, context=c0)  # from the world's generator, seeded by the simulator
        self.episode = None
        self.context = c0
        self.n_frames = 0
        self.reward = 0.0

    def step(self, next_context):
        if next_context is None:
            ep = self._first
        elif next_context == self.context and self.params.episodes_on_engage > 1:
            ep = _stay(self.world, next_context, self.params.episodes_on_engage)
        else:
            ep = self.world.step(next_context)[0]
        self.episode, self.context, self.n_frames, self.reward = ep, ep.context, len(ep.frames), float(ep.reward)
        return ep, self.context, self.reward

    def record(self):
        return (self.context, self.n_frames, self.reward)

    def record_frames(self):
        return self.episode.states[:, None]


def _stay(world, context: int, n: int):
    """``n`` visits of ``context`` as one block: :meth:`World.visits`, or for an object that only has
    ``step`` (any world with gymnasium's reset/step), its ``n`` episodes joined."""
    if isinstance(world, World):
        return world.visits(context, n)
    return concatenate_episodes([world.step(context)[0] for _ in range(n)])
