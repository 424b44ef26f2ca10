"""VTA: learning progress measured state by state — the drop of the error where the visit learned."""

from __future__ import annotations

from .base import Signal, register
from .vta import LearningProgressParams, VTARole, is_nan

__all__ = ["StateProgressVTA"]


@register("vta.state_progress")
class StateProgressVTA(VTARole):
    """DA = HPC's ``progress``: the drop of the adaptive module's eq-10 error at the states
    this episode showed, since those states' previous visit, per frame; ``boredom`` (-100)
    when the episode is familiar, 0 while undefined. A variant of section 2.5, not the
    paper's reading.

    Section 2.5 takes learning progress as the negative derivative of eq 11, the sum of the
    stored errors of a context's states. A visit changes only the terms of the states it
    shows, so eq 11's decrease over the visit is the sum of those states' drops;
    divided by the frames that had a previous error, it is a rate of progress per frame
    learned. :class:`~neurocur.regions.vta.LearningProgressVTA` instead compares one
    error of the context with the one of its previous visit: the context mean (eq 11 / M)
    is diluted by the states the visit did not show and a two-visit block changes twice
    as many terms; the episode's mean error compares the previous visit's states with
    this visit's, which do not tell staying from leaving (docs/reproduction.md, section
    2.8, "What the episode reward compares").

    Reads the role's ports and ``progress`` (``HPC.progress``, wired by
    ``circuits/vta_state_progress.toml``); the error, module-learned and reward inputs are
    accepted and ignored (HPC's stored errors start afresh with each adaptive module).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"StateProgressVTA"``); the constructor is ``Region``'s.
    params : LearningProgressParams, optional
        ``boredom`` (default -100), the DA of a familiar (gated) episode, in reward units.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = LearningProgressParams
    inputs = (*VTARole.inputs, Signal("progress", "float64", (), "HPC's same-state drop of the error, per frame"))

    def dopamine(self, context, reward_error, familiar, module_learned, reward, progress):
        if familiar:
            return self.params.boredom
        return 0.0 if is_nan(progress) else float(progress)

    def step(self, context, reward_error, familiar, module_learned, reward, progress):
        return self.release(self.dopamine(context, reward_error, familiar, module_learned, reward, progress))
