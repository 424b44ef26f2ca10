"""VTA: learning progress on the slow-feature objective — the drop of the slowest output's Δ."""

from __future__ import annotations

from .base import Signal, register
from .vta import VTARole
from .vta_state_progress import StateProgressVTA

__all__ = ["SlownessProgressVTA"]


@register("vta.slowness_progress")
class SlownessProgressVTA(StateProgressVTA):
    """DA = EC's ``slowness_progress``: how much slower the adaptive module's slowest output
    has become on the visited context since its previous visit (eq 4's Δ, on this episode's
    frames); ``boredom`` (-100) when the episode is familiar, 0 while undefined. A variant, not
    the paper's reading: section 2.5 derives the reward from the estimation error (eq 11),
    section 4.4 quantifies learning progress as the convergence of this output (Ω, eqs 16-17).
    Wired by ``circuits/vta_slowness_progress.toml``; the dopamine rule is
    :class:`~neurocur.regions.vta_state_progress.StateProgressVTA`'s, only the progress read differs.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"SlownessProgressVTA"``); the constructor is ``Region``'s.
    params : LearningProgressParams, optional
        ``boredom`` (default -100), the DA of a familiar (gated) episode, in reward units.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    inputs = (*VTARole.inputs, Signal("progress", "float64", (), "EC's drop of the slowest output's delta"))
