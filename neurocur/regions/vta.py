"""VTA: dopamine — the role's shared ports, learning progress (section 2.5) and count novelty.

Every VTA model reads the same inputs (the context, HPC's error and familiarity signals,
the module-learned event and the world's extrinsic reward of the visit) and releases one
level of dopamine per episode, so each drops into the VTA's place in a circuit
(``[replace.VTA] type = "vta.surprise"``). The other models are in ``vta_*.py``;
docs/regions.md gives every model's equations, parameters and references.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register

__all__ = ["VTARole", "LearningProgressVTA", "AbsLearningProgressVTA", "NoveltyVTA", "is_nan"]


def is_nan(x: float) -> bool:
    """True for NaN (an undefined error); cheaper than ``math.isnan`` on Python floats.

    Parameters
    ----------
    x : float
        The value.

    Returns
    -------
    bool
        Whether ``x`` is NaN (the only value not equal to itself).
    """
    return x != x


class VTARole(Region):
    """The VTA role's ports, shared by every VTA model.

    Inputs: ``context``, ``reward_error`` (HPC's error of the adaptive module after this
    episode, NaN while undefined), ``familiar`` (a stored module gates the episode),
    ``module_learned`` (the adaptive module is stored at this episode) and ``reward`` (the
    extrinsic reward the world paid for this visit, 0 unless the experiment declares one).
    Output and probe: ``da``. A model computes the level in :meth:`dopamine`; :meth:`step`
    releases it through :meth:`~neurocur.regions.base.Region.modulate` (drug lesions act
    there), then emits and records the released level.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"VTARole"``); the constructor is ``Region``'s.
    params : NoParams, optional
        The role has none (``NoParams``); each model sets its own ``Params``.
    **kwargs
        A model subclass's parameters as keywords, when ``params`` is not given (the role itself takes none).
    """

    modulator = "da"
    inputs = (
        Signal("context", "int64", ()),
        Signal("reward_error", "float64", (), "the adaptive module's error after this episode"),
        Signal("familiar", "bool", ()),
        Signal("module_learned", "bool", ()),
        Signal("reward", "float64", (), "extrinsic reward the world paid for this visit"),
    )
    outputs = (Signal("da", "float64", (), "dopamine released at this episode"),)
    probes = (Probe("da", "float", "reward units per episode", "dopamine released at this episode"),)

    def bind(self, world) -> None:
        self.n_contexts = world.n_contexts

    def reset(self, rng) -> None:
        self.da = 0.0

    def dopamine(self, context, reward_error, familiar, module_learned, reward) -> float:
        """The level this model computes for the episode, before any drug."""
        raise NotImplementedError

    def step(self, context, reward_error, familiar, module_learned, reward=0.0):
        return self.release(self.dopamine(context, reward_error, familiar, module_learned, reward))

    def release(self, level: float) -> tuple[float]:
        """Pass ``level`` through the drugs, keep it for the probe and emit it."""
        self.da = float(self.modulate(level))
        return (self.da,)

    def record(self):
        return (self.da,)


@dataclass(frozen=True)
class LearningProgressParams:
    boredom: float = param(-100.0, float, doc="DA of a familiar (gated) episode (reward units)")

    def __post_init__(self):
        check_params(self)


@register("vta.learning_progress")
class LearningProgressVTA(VTARole):
    """DA = learning progress: ``e_prev(c) - e(c)`` (the negative derivative of eq 11).

    ``e_prev(c)`` is the context's error measured at its previous visit (with the
    same adaptive module). DA is 0 on the first visit or while either value is
    undefined, and ``boredom`` (-100) when the episode is familiar (section 4.1.2).
    The memory of previous errors is cleared when a module is stored (the next
    adaptive module starts a new error table).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"LearningProgressVTA"``); the constructor is ``Region``'s.
    params : LearningProgressParams, optional
        ``boredom`` (default -100), the DA of a familiar (gated) episode, in reward units.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = LearningProgressParams

    def reset(self, rng) -> None:
        super().reset(rng)
        self.previous = np.full(self.n_contexts, np.nan)

    def progress(self, before: float, after: float) -> float:
        """The reward of an error change ``before -> after``: its decrease."""
        return before - after

    def dopamine(self, context, reward_error, familiar, module_learned, reward):
        before = self.previous[context]
        if familiar:
            da = self.params.boredom
        else:
            da = self.progress(before, reward_error)
            if is_nan(da):  # either error undefined
                da = 0.0
        if not is_nan(reward_error):
            self.previous[context] = reward_error
        if module_learned:
            self.previous[:] = np.nan
        return float(da)


@register("vta.abs_learning_progress")
class AbsLearningProgressVTA(LearningProgressVTA):
    """DA = ``|e_prev(c) - e(c)|``: the absolute learning progress of Oudeyer, Kaplan & Hafner
    (2007, IEEE Trans. Evol. Comput. 11:265), rewarding any change of the error, a fall or a
    rise. Everything else (boredom, undefined errors, the memory cleared on storage) is
    the signed model's (:class:`LearningProgressVTA`).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"AbsLearningProgressVTA"``); the constructor is ``Region``'s.
    params : LearningProgressParams, optional
        ``boredom`` (default -100), the DA of a familiar (gated) episode, in reward units.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    def progress(self, before: float, after: float) -> float:
        return abs(before - after)


@dataclass(frozen=True)
class NoveltyParams:
    scale: float = param(1.0, float, low=0.0, low_open=True, doc="DA of the first visit (reward units)")

    def __post_init__(self):
        check_params(self)


@register("vta.novelty")
class NoveltyVTA(VTARole):
    """DA = count-based novelty ``scale / sqrt(N(c))``, N(c) = visits of context c so far
    (this one included). No boredom term; the other inputs are accepted and ignored so
    that it drops into the learning-progress VTA's place.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"NoveltyVTA"``); the constructor is ``Region``'s.
    params : NoveltyParams, optional
        ``scale`` (> 0, default 1), the DA of a context's first visit, in reward units.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = NoveltyParams

    def reset(self, rng) -> None:
        super().reset(rng)
        self.visits = np.zeros(self.n_contexts, dtype=np.int64)

    def dopamine(self, context, reward_error, familiar, module_learned, reward):
        self.visits[context] += 1
        return self.params.scale / float(np.sqrt(self.visits[context]))
