"""ACh as expected uncertainty: one minus the estimated validity of the cue believed relevant.

Yu & Dayan (2005, Neuron 46:681), the approximate inference of their generalised attention
task (:mod:`neurocur.contexts.posner`): the observer keeps one believed-relevant cue mu*
(held by the NE region, :mod:`.ne_uncertainty`) and an estimate gamma* of its validity,
and ACh reports the expected uncertainty, the probability that the cue misleads:

    (Y1)  ACh_t = 1 - gamma*_t.

gamma*_t is the posterior mean of the validity under a Beta(a, b) prior, from the trials
since mu* was adopted, of which k were valid (the target on mu*'s side) out of n:

    (Y2)  gamma*_t = (k + a) / (n + a + b).

When the NE region reports a switch (the context is believed to have changed), the counts
restart from what is known of the new cue: its agreements with the target over the NE
region's memory of recent trials (``support``: k valid of n). The paper estimates gamma*
from the trials since the context was last believed to change as well; that the estimate
is a Beta posterior mean, its prior, and the restart from the recent trials are our
reading, their text was not available to check (docs/validation.md, section 4).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..config import check_params, param
from ..contexts.posner import cues_of, target_column, validity_column
from .base import Probe, Region, Signal, register

__all__ = ["ExpectedUncertaintyACh", "believed_validity"]


def believed_validity(ach: float) -> float:
    """The validity the released ACh stands for, gamma = 1 - ACh (Y1), clipped to [0.5, 1]: the task
    never makes a cue anti-predictive, so a drug that raises ACh above 0.5 leaves the cue uninformative.

    Parameters
    ----------
    ach : float
        The released ACh level (after any drug).

    Returns
    -------
    float
        gamma in [0.5, 1].
    """
    return min(1.0, max(0.5, 1.0 - float(ach)))


@dataclass(frozen=True)
class ACHParams:
    prior_valid: float = param(1.0, float, low=0.0, low_open=True, doc="a, Beta prior pseudo-count of valid trials")
    prior_invalid: float = param(1.0, float, low=0.0, low_open=True, doc="b, Beta prior pseudo-count of invalid trials")

    def __post_init__(self):
        check_params(self)


@register("ach.expected_uncertainty")
class ExpectedUncertaintyACh(Region):
    """ACh = 1 - gamma*, the expected uncertainty of the believed-relevant cue (module docstring, Y1-Y2).

    Step: ACh from the counts of the trials before this one, through the drugs (``modulator``
    ``"ach"``: clamp, scale, noise act on what the NE region and the decision read). Learn (after
    the trial, with the NE region's ``attended`` cue mu* of this trial, its ``switched`` and
    ``support``): a switch restarts the counts at ``support`` (k, n); otherwise the trial is
    counted, valid when the target (column ``cues`` of the frame) is on the side of cue mu*. Recorded: ``ach`` (released),
    ``gamma_star`` (the estimate before the drugs) and ``validity`` (the true validity of the
    trial, the world's marker, for the analysis only).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"ExpectedUncertaintyACh"``); the constructor is ``Region``'s.
    params : ACHParams, optional
        ``prior_valid`` (a) and ``prior_invalid`` (b), the Beta prior's pseudo-counts of valid and
        invalid trials (each > 0, default 1; Y2).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = ACHParams
    modulator = "ach"
    inputs = (Signal("episode", "Episode", (), "one trial: cues, target, markers (1, 2 h + 2)"),)
    learn_inputs = (
        Signal("episode", "Episode", (), "the same trial, its target now shown"),
        Signal("attended", "int64", (), "mu*, the cue believed relevant during the trial"),
        Signal("switched", "bool", (), "the NE region believed the context changed on this trial"),
        Signal("support", "int64", (2,), "after a switch: the new cue's agreements and trials over the NE's memory"),
    )
    outputs = (Signal("ach", "float64", (), "expected uncertainty, 1 - gamma* (after the drugs)"),)
    probes = (
        Probe("ach", "float", "probability", "released ACh, 1 - gamma* through the drugs"),
        Probe("gamma_star", "float", "probability", "gamma*, the estimated validity of the believed cue"),
        Probe("validity", "float", "probability", "the relevant cue's true validity (world marker)"),
    )

    def bind(self, world) -> None:
        self.cues = cues_of(world, self.name)

    def reset(self, rng) -> None:
        self.valid = 0
        self.trials = 0
        self._rec = (float("nan"),) * 3

    @property
    def gamma_star(self) -> float:
        """Y2: the Beta posterior mean of the validity of mu* from the trials since it was adopted."""
        p = self.params
        return (self.valid + p.prior_valid) / (self.trials + p.prior_valid + p.prior_invalid)

    def step(self, episode):
        gamma = self.gamma_star
        ach = self.modulate(1.0 - gamma)
        self._rec = (ach, gamma, float(episode.frames[0, validity_column(self.cues)]))
        return (ach,)

    def learn(self, episode, attended, switched, support):
        if switched:
            self.valid, self.trials = int(support[0]), int(support[1])
            return
        frame = episode.frames[0]
        self.trials += 1
        self.valid += int(frame[int(attended)] == frame[target_column(self.cues)])

    def record(self):
        return self._rec

