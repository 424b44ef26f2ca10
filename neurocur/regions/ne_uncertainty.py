"""NE as unexpected uncertainty: the belief that the relevant cue has changed, and the switch it triggers.

Yu & Dayan (2005, Neuron 46:681), the approximate inference of their generalised attention
task (:mod:`neurocur.contexts.posner`): the observer attends one cue mu* at a time, with
the validity gamma* that ACh reports (:mod:`.ach`, gamma* = 1 - ACh). lambda_t is the
posterior probability that mu* is still the relevant cue after trial t; the context
persists from one trial to the next with probability 1 - q (the observer's change
probability), and when it has changed the attended cue agrees with the target only by
chance (1/2). After the trial's target S_t is shown, with v_t = 1 when S_t is on mu*'s side:

    (Y3)  lambda'_t = (1 - q) lambda_{t-1}
    (Y4)  lambda_t = lambda'_t L_t / (lambda'_t L_t + (1 - lambda'_t) / 2),
          L_t = gamma* if v_t else 1 - gamma*,

and NE reports the unexpected uncertainty, the probability that the context has changed:

    (Y5)  NE_t = 1 - lambda_t.

The ACh/NE interaction: the observer concludes that the context has changed when

    (Y6)  NE_t > ACh_t / (0.5 + ACh_t),

a threshold that rises with ACh: the less valid the cue is known to be, the more
evidence against it is put down to expected uncertainty. (Y6 is the paper's rule; it is
where lambda_t L'/(lambda_t L' + (1 - lambda_t)/2) would fall below 1/2 on one more invalid
trial, L' = 1 - gamma* = ACh.) On a switch the observer re-initialises: lambda = lambda_0
(``reset_belief``), mu* becomes the cue that agreed with the target most often over the
last ``memory`` trials, this one included (ties broken at random; it may be mu* again),
and ACh's counts restart from that cue's agreements over them (:mod:`.ach`). Y3-Y5 follow from their generative model; the
reset values and the choice of the new cue are ours, the paper's text was not available
to check them (docs/validation.md, section 4).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from ..contexts.posner import cues_of, relevant_columns, target_column
from .ach import believed_validity
from .base import Probe, Region, Signal, register

__all__ = ["UnexpectedUncertaintyNE"]


@dataclass(frozen=True)
class NEParams:
    change_probability: float = param(0.01, float, low=0.0, high=1.0, high_open=True,
                                      doc="q, the observer's probability that the context changes before a trial")
    reset_belief: float = param(0.9, float, low=0.0, high=1.0, low_open=True,
                                doc="lambda_0, the belief in the newly chosen cue after a switch")
    memory: int = param(20, int, low=1, doc="trials over which the new cue's agreement with the target is counted")
    threshold_offset: float = param(0.5, float, low=0.0, low_open=True,
                                    doc="the 0.5 of the switch threshold ACh / (0.5 + ACh) (Y6)")

    def __post_init__(self):
        check_params(self)


@register("ne.unexpected_uncertainty")
class UnexpectedUncertaintyNE(Region):
    """NE = 1 - lambda, the posterior that the attended cue is no longer the relevant one, and the
    switch when it exceeds ACh / (0.5 + ACh) (module docstring, Y3-Y6).

    Step (after the trial's target is shown): ``attended`` is mu* during the trial (what the
    decision and ACh's counts use), lambda is updated by Y3-Y4 with gamma* = 1 - ACh (the
    released ACh, clipped to [0.5, 1]), NE = 1 - lambda through the drugs (``modulator``
    ``"ne"``), and ``switched`` is Y6 with the released NE and ACh; ``support`` is, after a
    switch, the new cue's agreements with the target and the trials counted over the memory
    ((0, 0) otherwise). mu* starts at random, with lambda = lambda_0. Recorded: ``ne`` (released), ``attended``, ``switched``, and from the
    world's markers, for the analysis only: ``relevant`` (the true relevant cue) and
    ``changed`` (it differs from the previous trial's).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"UnexpectedUncertaintyNE"``); the constructor is ``Region``'s.
    params : NEParams, optional
        ``change_probability`` (q, in [0, 1), default 0.01), the observer's probability that the context
        changes before a trial (Y3); ``reset_belief`` (lambda_0, in (0, 1], default 0.9), the belief in
        the cue chosen after a switch; ``memory`` (default 20), the trials over which the new cue's
        agreement with the target is counted; ``threshold_offset`` (> 0, default 0.5), the 0.5 of the
        switch threshold ACh / (0.5 + ACh) (Y6).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = NEParams
    modulator = "ne"
    inputs = (
        Signal("episode", "Episode", (), "one trial: cues, target, markers (1, 2 h + 2)"),
        Signal("ach", "float64", (), "released ACh, 1 - gamma*"),
    )
    outputs = (
        Signal("ne", "float64", (), "unexpected uncertainty, 1 - lambda (after the drugs)", optional=True),
        Signal("attended", "int64", (), "mu*, the cue believed relevant during this trial"),
        Signal("switched", "bool", (), "the context is believed to have changed (Y6)"),
        Signal("support", "int64", (2,), "after a switch: the new cue's agreements with the target and the "
               "trials counted, over the memory"),
    )
    probes = (
        Probe("ne", "float", "probability", "released NE, 1 - lambda through the drugs"),
        Probe("attended", "int", "cue", "mu*, the cue believed relevant during the trial"),
        Probe("switched", "bool", "", "NE exceeded ACh / (0.5 + ACh): the observer re-initialised"),
        Probe("relevant", "int", "cue", "the true relevant cue (world marker)"),
        Probe("changed", "bool", "", "the true relevant cue changed before this trial (world marker)"),
    )

    def bind(self, world) -> None:
        self.cues = cues_of(world, self.name)

    def reset(self, rng) -> None:
        self.rng = rng
        self.cue = int(rng.integers(self.cues))
        self.belief = self.params.reset_belief
        self.agreement = deque(maxlen=self.params.memory)
        self.previous_relevant = -1
        self._rec = (float("nan"), -1, False, -1, False)

    def update_belief(self, valid: bool, gamma: float) -> float:
        """Y3-Y4: lambda after one trial whose target was (``valid``) or was not on mu*'s side."""
        prior = (1.0 - self.params.change_probability) * self.belief
        likelihood = gamma if valid else 1.0 - gamma
        return prior * likelihood / (prior * likelihood + 0.5 * (1.0 - prior))

    def step(self, episode, ach):
        frame = episode.frames[0]
        cues, target = frame[:self.cues], frame[target_column(self.cues)]
        attended = self.cue
        self.agreement.append(cues == target)
        self.belief = self.update_belief(bool(cues[attended] == target), believed_validity(ach))
        ne = self.modulate(1.0 - self.belief)
        level = max(0.0, float(ach))  # a noise drug may push the released level below 0
        switched = bool(ne > level / (self.params.threshold_offset + level))
        support = np.zeros(2, dtype=np.int64)
        if switched:
            votes = np.sum(self.agreement, axis=0)
            self.cue = int(self.rng.choice(np.flatnonzero(votes == votes.max())))
            self.belief = self.params.reset_belief
            support[:] = votes[self.cue], len(self.agreement)
        relevant = int(np.argmax(frame[relevant_columns(self.cues)]))
        changed = self.previous_relevant >= 0 and relevant != self.previous_relevant
        self.previous_relevant = relevant
        self._rec = (ne, attended, switched, relevant, changed)
        return (ne, attended, switched, support)

    def record(self):
        return self._rec
