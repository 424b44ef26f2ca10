"""VTA: the temporal-difference reward prediction error over the world's extrinsic reward."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import register
from .vta import VTARole

__all__ = ["TDVTA"]


@dataclass(frozen=True)
class TDParams:
    rate: float = param(0.1, float, low=0.0, high=1.0, low_open=True, doc="alpha, TD(0) learning rate of V")
    discount: float = param(0.9, float, low=0.0, high=1.0, high_open=True, doc="gamma, discount per episode")

    def __post_init__(self):
        check_params(self)


@register("vta.td")
class TDVTA(VTARole):
    """DA = the reward prediction error ``delta = r + gamma V(c') - V(c)`` of TD(0)
    (Schultz, Dayan & Montague 1997, Science 275:1593; Sutton & Barto 1998, eq 6.2).

    The state is the context: ``c`` the previous episode's, ``c'`` this one's, ``r`` the
    extrinsic reward the world paid for this visit (the ``reward`` input). ``V`` (one value
    per context, 0 at the start, reward units) learns from the released dopamine,
    ``V(c) <- V(c) + alpha · DA``, so a drug on DA acts on what it teaches too. On the
    first episode there is no previous state: DA = ``r`` and nothing is learned. The
    intrinsic inputs are accepted and ignored: without an extrinsic reward DA is 0.
    With one reward ``r`` on every visit, ``V`` tends to ``r / (1 - gamma)``.
    """

    Params = TDParams

    def reset(self, rng) -> None:
        super().reset(rng)
        self.value = np.zeros(self.n_contexts)
        self.previous = -1

    def dopamine(self, context, reward_error, familiar, module_learned, reward):
        if self.previous < 0:
            return float(reward)
        return float(reward + self.params.discount * self.value[context] - self.value[self.previous])

    def step(self, context, reward_error, familiar, module_learned, reward=0.0):
        out = super().step(context, reward_error, familiar, module_learned, reward)
        if self.previous >= 0:
            self.value[self.previous] += self.params.rate * self.da
        self.previous = int(context)
        return out
