"""VTA: content novelty — dopamine that falls as the content of a context becomes represented."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import register
from .vta import VTARole, is_nan

__all__ = ["ContentNoveltyVTA"]


@dataclass(frozen=True)
class ContentNoveltyParams:
    scale: float = param(1.0, float, low=0.0, low_open=True, doc="DA of wholly novel content (reward units)")

    def __post_init__(self):
        check_params(self)


@register("vta.content_novelty")
class ContentNoveltyVTA(VTARole):
    """DA = ``scale · min(1, e(c) / e_0(c))``: the share of the context's content that the
    memory does not yet represent (the hippocampal mismatch that drives VTA novelty
    responses, Lisman & Grace 2005, Neuron 46:703).

    ``e(c)`` is HPC's error of the adaptive module (``reward_error``, eq 10/11) and
    ``e_0(c)`` the first defined error of context ``c`` under the current adaptive module.
    DA is ``scale`` while the error is undefined (nothing of the content is represented
    yet) and 0 on a familiar episode (a stored module represents the content). The
    first errors are forgotten when a module is stored: the next adaptive module starts
    from nothing. Unlike count novelty (:class:`~neurocur.regions.vta.NoveltyVTA`) it
    falls only as the error falls, not with visits: it stays high on an unlearnable
    context, and a context whose content another context taught is familiar at once.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"ContentNoveltyVTA"``); the constructor is ``Region``'s.
    params : ContentNoveltyParams, optional
        ``scale`` (> 0, default 1), the DA of wholly novel content, in reward units.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = ContentNoveltyParams

    def reset(self, rng) -> None:
        super().reset(rng)
        self.first = np.full(self.n_contexts, np.nan)

    def dopamine(self, context, reward_error, familiar, module_learned, reward):
        first = self.first[context]
        if familiar:
            novelty = 0.0
        elif is_nan(reward_error):
            novelty = 1.0
        elif is_nan(first):
            self.first[context] = reward_error
            novelty = 1.0
        else:
            novelty = min(1.0, reward_error / first) if first > 0.0 else 0.0
        if module_learned:
            self.first[:] = np.nan
        return self.params.scale * float(novelty)
