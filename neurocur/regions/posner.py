"""Target detection in the Posner task: the cue's prior and noisy sensory samples, to a posterior bound.

After Yu & Dayan (2005, Neuron 46:681, "Probabilistic cueing"): the cue sets a prior on
the target's side, P(S = c_mu*) = gamma* = 1 - ACh (:mod:`.ach`; the cue mu* the NE region
attends, :mod:`.ne_uncertainty`), and the observer combines it with sensory evidence about
the target, so that a validly cued target is detected sooner and more accurately than an
invalidly cued one: the validity effect. How the paper turns the prior into reaction
times we could not check; here the evidence arrives as samples x_k ~ N(2 S - 1, sigma^2)
(S = 1 right, 0 left), each adding its log-likelihood ratio 2 x_k / sigma^2 to the
log-odds of "right", which start at the prior's

    (Y7)  l_0 = +/- log(gamma* / (1 - gamma*))   (+ when mu* points right),

and the observer responds when the posterior of one side reaches ``bound``, |l_n| >=
log(bound / (1 - bound)) (a sequential probability ratio test, Wald 1947): the reaction
time is n, the samples taken (``max_samples`` at most, then the sign of l decides). By
Wald's identity E[n] ~ (E[l_n] - l_0) / (2 / sigma^2), so the validity effect grows with
|l_0|, i.e. with gamma*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from ..contexts.posner import cues_of, relevant_columns, target_column
from .ach import believed_validity
from .base import Probe, Region, Signal, register

__all__ = ["PosnerDecision"]


@dataclass(frozen=True)
class PosnerParams:
    noise: float = param(2.0, float, low=0.0, low_open=True, doc="sigma, standard deviation of a sensory sample")
    bound: float = param(0.99, float, low=0.5, high=1.0, low_open=True, high_open=True,
                         doc="posterior probability of a side at which the observer responds")
    max_samples: int = param(200, int, low=1, doc="samples at most; then the sign of the log-odds decides")

    def __post_init__(self):
        check_params(self)


@register("decision.posner")
class PosnerDecision(Region):
    """The cue's prior and sensory samples to a posterior bound (module docstring, Y7).

    Per pass (one trial): the prior from the released ACh (gamma* = 1 - ACh, clipped to
    [0.5, 1]) and the attended cue; samples from the region's generator. Recorded: ``valid``
    (the target is on the side of the truly relevant cue: the experimenter's valid trial),
    ``cued`` (on the side of the attended cue), ``rt`` (samples to the response),
    ``correct`` (the response is the target's side) and ``prior`` (the prior probability the
    observer gave the target's actual side).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"PosnerDecision"``); the constructor is ``Region``'s.
    params : PosnerParams, optional
        ``noise`` (sigma > 0, default 2), the standard deviation of a sensory sample; ``bound`` (in
        (0.5, 1), default 0.99), the posterior probability of a side at which the observer responds;
        ``max_samples`` (default 200), the samples at most, after which the sign of the log-odds decides.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = PosnerParams
    inputs = (
        Signal("episode", "Episode", (), "one trial: cues, target, markers (1, 2 h + 2)"),
        Signal("ach", "float64", (), "released ACh, 1 - gamma*"),
        Signal("attended", "int64", (), "mu*, the cue believed relevant"),
    )
    probes = (
        Probe("valid", "bool", "", "the target is on the relevant cue's side (the experimenter's valid trial)"),
        Probe("cued", "bool", "", "the target is on the attended cue's side"),
        Probe("rt", "int", "samples", "sensory samples until the posterior reached the bound"),
        Probe("correct", "bool", "", "the response is the target's side"),
        Probe("prior", "float", "probability", "prior probability of the target's actual side"),
    )

    def bind(self, world) -> None:
        self.cues = cues_of(world, self.name)

    def reset(self, rng) -> None:
        self.rng = rng
        self._rec = (False, False, -1, False, float("nan"))

    def step(self, episode, ach, attended):
        p = self.params
        frame = episode.frames[0]
        target = frame[target_column(self.cues)]
        gamma = believed_validity(ach)
        side = 1.0 if frame[int(attended)] > 0.5 else -1.0
        start = side * math.log(gamma / (1.0 - gamma)) if gamma < 1.0 else side * math.inf
        bound = math.log(p.bound / (1.0 - p.bound))
        samples = (2.0 * target - 1.0) + p.noise * self.rng.standard_normal(p.max_samples)
        log_odds = start + np.cumsum(2.0 * samples / p.noise ** 2)
        crossed = np.flatnonzero(np.abs(log_odds) >= bound)
        n = int(crossed[0]) + 1 if len(crossed) else p.max_samples
        response = 1.0 if log_odds[n - 1] > 0 else 0.0
        relevant = int(np.argmax(frame[relevant_columns(self.cues)]))
        prior = gamma if frame[int(attended)] == target else 1.0 - gamma
        self._rec = (bool(frame[relevant] == target), bool(frame[int(attended)] == target), n,
                     bool(response == target), float(prior))
        return ()

    def record(self):
        return self._rec
