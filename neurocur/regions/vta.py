"""VTA: dopamine as intrinsic reward — learning progress (section 2.5) or a novelty variant."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register

_INPUTS = (
    Signal("context", "int64", ()),
    Signal("reward_error", "float64", (), "the adaptive module's error after this episode"),
    Signal("familiar", "bool", ()),
    Signal("module_learned", "bool", ()),
)
_OUTPUTS = (Signal("da", "float64", (), "intrinsic reward of this episode"),)
_PROBES = (Probe("da", "float", "error units per episode", "dopamine: intrinsic reward of this episode"),)


@dataclass(frozen=True)
class LearningProgressParams:
    boredom: float = param(-100.0, float, doc="reward of a familiar (gated) episode")

    def __post_init__(self):
        check_params(self)


@register("vta.learning_progress")
class LearningProgressVTA(Region):
    """DA = learning progress: ``e_prev(c) - e(c)`` (the negative derivative of eq 11).

    ``e_prev(c)`` is the context's error measured at its previous visit (with the
    same adaptive module). DA is 0 on the first visit or while either value is
    undefined, and ``boredom`` (-100) when the episode is familiar (section 4.1.2).
    The memory of previous errors is cleared when a module is stored (the next
    adaptive module starts a new error table).
    """

    Params = LearningProgressParams
    inputs, outputs, probes = _INPUTS, _OUTPUTS, _PROBES

    def bind(self, world) -> None:
        self.n_contexts = world.n_contexts

    def reset(self, rng) -> None:
        self.previous = np.full(self.n_contexts, np.nan)
        self.da = 0.0

    def step(self, context, reward_error, familiar, module_learned):
        before = self.previous[context]
        if familiar:
            da = self.params.boredom
        else:
            da = before - reward_error
            if da != da:  # NaN: either error undefined
                da = 0.0
        if reward_error == reward_error:
            self.previous[context] = reward_error
        if module_learned:
            self.previous[:] = np.nan
        self.da = float(da)
        return (self.da,)

    def record(self):
        return (self.da,)


@dataclass(frozen=True)
class NoveltyParams:
    scale: float = param(1.0, float, low=0.0, low_open=True, doc="DA of the first visit")

    def __post_init__(self):
        check_params(self)


@register("vta.novelty")
class NoveltyVTA(Region):
    """DA = count-based novelty ``scale / sqrt(N(c))``, N(c) = visits of context c so far
    (this one included). No boredom term; the error inputs are accepted and ignored so
    that it drops into the learning-progress VTA's place."""

    Params = NoveltyParams
    inputs, outputs, probes = _INPUTS, _OUTPUTS, _PROBES

    def bind(self, world) -> None:
        self.n_contexts = world.n_contexts

    def reset(self, rng) -> None:
        self.visits = np.zeros(self.n_contexts, dtype=np.int64)
        self.da = 0.0

    def step(self, context, reward_error, familiar, module_learned):
        self.visits[context] += 1
        self.da = self.params.scale / float(np.sqrt(self.visits[context]))
        return (self.da,)

    def record(self):
        return (self.da,)
