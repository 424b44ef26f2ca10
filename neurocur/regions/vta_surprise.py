"""VTA: surprise — dopamine as the magnitude of the prediction error itself."""

from __future__ import annotations

from dataclasses import dataclass

from ..config import check_params, param
from .base import register
from .vta import VTARole, is_nan

__all__ = ["SurpriseVTA"]


@dataclass(frozen=True)
class SurpriseParams:
    scale: float = param(1.0, float, low=0.0, low_open=True,
                         doc="DA per unit of error (reward units per feature distance)")

    def __post_init__(self):
        check_params(self)


@register("vta.surprise")
class SurpriseVTA(VTARole):
    """DA = ``scale · e(c)``: the error of the agent's model of the context, rewarded as such
    (Schmidhuber 1991, "Curious model-building control systems", Proc. IJCNN 2:1458 — the
    curiosity that noise attracts, because its error never falls).

    ``e(c)`` is HPC's error of the adaptive module (``reward_error``, eq 10/11). On a
    familiar episode a stored module predicts the content (its error is below HPC's
    threshold), so the agent is not surprised: DA = 0. DA is 0 while the error is
    undefined. No memory across episodes.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"SurpriseVTA"``); the constructor is ``Region``'s.
    params : SurpriseParams, optional
        ``scale`` (> 0, default 1), the DA per unit of error (reward units per feature distance).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = SurpriseParams

    def dopamine(self, context, reward_error, familiar, module_learned, reward):
        if familiar or is_nan(reward_error):
            return 0.0
        return self.params.scale * float(reward_error)
