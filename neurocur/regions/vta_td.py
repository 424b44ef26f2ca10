"""VTA: the temporal-difference reward prediction error over the world's extrinsic reward, per episode
(:class:`TDVTA`) or per time step of a trial (:class:`TDTrialVTA`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register
from .vta import VTARole

__all__ = ["TDVTA", "TDTrialVTA"]


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

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"TDVTA"``); the constructor is ``Region``'s.
    params : TDParams, optional
        ``rate`` (alpha, in (0, 1], default 0.1), the TD(0) learning rate of V; ``discount`` (gamma, in
        [0, 1), default 0.9), the discount per episode.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = TDParams

    @classmethod
    def reads_reward(cls, params) -> bool:
        return True

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


@dataclass(frozen=True)
class TDTrialParams:
    rate: float = param(0.1, float, low=0.0, high=1.0, low_open=True, doc="alpha, TD(0) learning rate of the weights")
    discount: float = param(0.98, float, low=0.0, high=1.0, doc="gamma, discount per time step")

    def __post_init__(self):
        check_params(self)


@register("vta_trial.td_csc")
class TDTrialVTA(Region):
    """DA within a trial: the TD error of every time step over a complete serial compound
    (Schultz, Dayan & Montague 1997, Science 275:1593; Montague, Dayan & Sejnowski
    1996, J Neurosci 16:1936; Sutton & Barto 1990).

    The episode is one trial of time steps, one frame each, its columns those of
    :mod:`neurocur.contexts.conditioning` (0 the cue, 1 the reward delivered, 2 the time the
    reward is due). As the FitzHugh-Nagumo LC runs sub-steps inside a pass, this model runs
    the trial's time steps inside the pass. The stimulus representation is the complete
    serial compound: x_i(t) = 1 when the cue came on i steps before t (i = 0 .. T - 1),
    so V(t) = w_i for that i, and V(t) = 0 before the cue. At every step t

        delta(t) = r(t) + gamma V(t) - V(t - 1),    w_i(t-1) <- w_i(t-1) + alpha delta(t)

    (the weight of the component active at t - 1), with r(t) = the trial's reward (input
    ``reward``, what the world paid) at the steps where column 1 is set (shared among them) and V(-1) the last value of the previous
    trial (0 once learned: no component is active past the trial's end). Each delta(t) is the
    dopamine released (through the drugs, before it teaches the weights).

    Recorded per trial: ``da`` the sum of delta over the trial; ``da_cue`` delta at the cue's
    onset; ``da_reward`` delta at the step the reward is due (column 2), delivered or not;
    ``da_baseline`` the mean delta before the cue; ``omitted`` whether the reward was due and
    not delivered. Weights start at 0, so on the first trial DA fires at the reward only.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"TDTrialVTA"``); the constructor is ``Region``'s.
    params : TDTrialParams, optional
        ``rate`` (alpha, in (0, 1], default 0.1), the TD(0) learning rate of the weights; ``discount``
        (gamma, in [0, 1], default 0.98), the discount per time step.
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = TDTrialParams
    modulator = "da"

    @classmethod
    def reads_reward(cls, params) -> bool:
        return True
    inputs = (
        Signal("episode", "Episode", (), "one trial: cue, reward delivered, reward due (T, 3)"),
        Signal("reward", "float64", (), "the reward the world paid for the trial"),
    )
    outputs = (Signal("da", "float64", (), "the trial's summed TD error", optional=True),)
    probes = (
        Probe("da", "float", "reward units", "sum of the TD errors of the trial"),
        Probe("da_cue", "float", "reward units", "TD error at the cue's onset"),
        Probe("da_reward", "float", "reward units", "TD error at the step the reward is due"),
        Probe("da_baseline", "float", "reward units", "mean TD error before the cue"),
        Probe("omitted", "bool", "", "the reward was due and not delivered"),
    )

    def bind(self, world) -> None:
        self.n_components = world.n_states

    def reset(self, rng) -> None:
        self.weights = np.zeros(self.n_components)
        self.last_value = 0.0
        self.last_component = -1
        self._rec = (0.0, 0.0, 0.0, 0.0, False)

    def step(self, episode, reward):
        p, frames = self.params, episode.frames
        cue_on = np.flatnonzero(frames[:, 0] > 0)
        onset = int(cue_on[0]) if len(cue_on) else len(frames)
        delivered = frames[:, 1] > 0
        r = np.where(delivered, reward / max(1, int(delivered.sum())), 0.0)
        delta = np.empty(len(frames))
        for t in range(len(frames)):
            i = t - onset
            component = i if 0 <= i < self.n_components else -1
            value = self.weights[component] if component >= 0 else 0.0
            delta[t] = self.modulate(r[t] + p.discount * value - self.last_value)
            if self.last_component >= 0:
                self.weights[self.last_component] += p.rate * delta[t]
            self.last_value = self.weights[component] if component >= 0 else 0.0
            self.last_component = component
        due = np.flatnonzero(frames[:, 2] > 0)
        at_due = float(delta[due[0]]) if len(due) else float("nan")
        baseline = float(delta[:onset].mean()) if onset > 0 else float("nan")
        at_cue = float(delta[onset]) if onset < len(frames) else float("nan")
        omitted = bool(len(due) and not delivered[due[0]])
        self._rec = (float(delta.sum()), at_cue, at_due, baseline, omitted)
        return (self._rec[0],)

    def record(self):
        return self._rec
