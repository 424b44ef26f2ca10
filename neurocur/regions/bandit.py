"""Choice among options learned from their outcomes: the delta rule and a softmax with perseveration and lapse.

Not in the paper. The reinforcement-learning model of a multi-armed bandit that fits people's
trial-by-trial choices (Sutton & Barto 2018, *Reinforcement Learning*, 2nd ed., sections 2.4
and 2.8; Daw 2011, "Trial-by-trial data analysis using computational models", in *Decision
Making, Affect, and Learning*, Attention and Performance XXIII; hBayesDM's ``bandit2arm_delta``
and ``bandit4arm``, Ahn, Haines & Zhang 2017). One scheduler pass is one trial:

1. ``bandit.delta`` (or ``bandit.delta_posneg``) emits the option values, after learning from
   the previous trial's outcome (delayed inputs): Q_k = Q0 before the first outcome, then
   ``Q_c <- Q_c + alpha (r - Q_c)`` for the chosen option c and its outcome r (eq 2.4 of Sutton &
   Barto); ``delta_posneg`` uses ``alpha_pos`` for a positive prediction error and ``alpha_neg``
   for a negative one.
2. ``bandit.softmax`` chooses this trial's option:
   ``P(k) = (1 - lapse) softmax_k(beta Q_k + kappa [k = previous choice]) + lapse / K``
   (:func:`option_log_probabilities`); kappa is in logit units (a perseveration bonus,
   Lau & Glimcher 2005), the lapse mixes the softmax with a uniform choice.
3. ``bandit.task`` (the clock) visits the chosen option in the world of options
   (:class:`~neurocur.contexts.options.OptionsWorld`), which pays its outcome.

The decision scores the choice of trial t from trials 0..t-1 and learns from trial t's outcome
after it, so the first trial's choice is scored from the initial values; a replay of people's
trials (:mod:`neurocur.fit.trials`) replaces the world's draws by the recorded outcomes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from ..config import check_params, param
from ..contexts.options import OptionsWorld
from .base import Probe, Region, Signal, register
from .lc import LCRole
from .lc_softmax import GAIN_PROBE
from .pfc import DISENGAGE, ENGAGE, reward_update


def option_log_probabilities(beta, values, previous, kappa, lapse):
    """log P(choose k) = log((1 - lapse) softmax_k(beta Q_k + kappa [k = previous]) + lapse / K).

    ``values``: (..., K) option values; ``previous``: the previous choice over the leading axes of
    ``values`` (-1: none, no bonus); ``beta``, ``kappa`` and ``lapse`` broadcast against those axes
    (a column of parameter sets against a row of trials gives (m, n, K)). The softmax is scipy's
    ``log_softmax`` (no underflow); with lapse 0 the mixture is the softmax itself, exactly."""
    v = np.asarray(values, dtype=np.float64)
    repeat = np.arange(v.shape[-1]) == np.asarray(previous)[..., None]
    z = np.asarray(beta, dtype=np.float64)[..., None] * v + np.asarray(kappa, dtype=np.float64)[..., None] * repeat
    lapse = np.asarray(lapse, dtype=np.float64)[..., None]
    with np.errstate(divide="ignore"):
        return np.logaddexp(np.log1p(-lapse) + special.log_softmax(z, axis=-1), np.log(lapse / v.shape[-1]))


@dataclass(frozen=True)
class DeltaParams:
    q0: float = param(0.0, float, low=-10.0, high=10.0, doc="Q0, every option's value before its first outcome "
                      "(outcome units)")
    alpha: float = param(0.3, float, low=0.0, high=1.0, doc="learning rate of the delta rule")

    def __post_init__(self):
        check_params(self)


@dataclass(frozen=True)
class DeltaPosNegParams:
    q0: float = param(0.0, float, low=-10.0, high=10.0, doc="Q0, every option's value before its first outcome "
                      "(outcome units)")
    alpha_pos: float = param(0.3, float, low=0.0, high=1.0, doc="learning rate after a positive prediction error")
    alpha_neg: float = param(0.3, float, low=0.0, high=1.0, doc="learning rate after a negative prediction error")

    def __post_init__(self):
        check_params(self)


@register("bandit.delta")
class DeltaValues(Region):
    """One value per option, Q0 at first; before each trial's choice, the previous trial's chosen
    option c moves toward its outcome r: ``Q_c <- Q_c + alpha (r - Q_c)`` (:func:`~.pfc.reward_update`)."""

    Params = DeltaParams
    inputs = (
        Signal("chosen", "int64", (), "the option chosen at the previous trial (None before the first)"),
        Signal("outcome", "float64", (), "the outcome of that choice"),
    )
    outputs = (Signal("values", "float64", ("n_contexts",), "each option's value before this trial's choice"),)
    probes = (Probe("prediction_error", "float", "outcome units", "outcome - value of the previous trial's choice, "
                    "learned before this trial (NaN on the first trial)"),)

    def bind(self, world) -> None:
        self.n_options = world.n_contexts

    def reset(self, rng) -> None:
        self.values = np.full(self.n_options, float(self.params.q0))
        self.delta = math.nan

    def rate(self, delta: float) -> float:
        """The learning rate of a prediction error ``delta``."""
        return self.params.alpha

    def step(self, chosen, outcome):
        self.delta = math.nan
        if chosen is not None:
            q = self.values[chosen]
            self.delta = float(outcome) - q
            self.values[chosen] = reward_update(q, float(outcome), self.rate(self.delta))
        return (self.values.copy(),)

    def record(self):
        return (self.delta,)


@register("bandit.delta_posneg")
class DeltaPosNegValues(DeltaValues):
    """:class:`DeltaValues` with a learning rate for each sign of the prediction error: ``alpha_pos``
    when the outcome beats the value, ``alpha_neg`` when it falls short (Frank et al. 2007, PNAS
    104:16311; Niv et al. 2012, J Neurosci 32:551)."""

    Params = DeltaPosNegParams

    def rate(self, delta: float) -> float:
        return self.params.alpha_pos if delta > 0 else self.params.alpha_neg


@dataclass(frozen=True)
class OptionChoiceParams:
    beta: float = param(3.0, float, low=0.0, high=50.0, doc="inverse temperature of the softmax (1 / outcome units)")
    kappa: float = param(0.0, float, low=-5.0, high=5.0, doc="perseveration: logit bonus for repeating the previous "
                         "choice (negative: alternation)")
    lapse: float = param(0.0, float, low=0.0, high=1.0, high_open=True, doc="probability of a uniform choice "
                         "instead of the softmax")

    def __post_init__(self):
        check_params(self)


@register("bandit.softmax")
class OptionChoice(LCRole):
    """This trial's option, drawn from :func:`option_log_probabilities` (one ``rng.choice``).

    Reads the option values and ``context``, the option chosen at the previous trial (None on the
    first). ``next_context`` is the chosen option (the clock visits it in the same pass), ``action``
    engage when it repeats the previous choice, disengage otherwise. The inverse temperature is
    released through the drugs (clipped at 0) as the NE gain of the LC models. The replay scores
    the chosen option (``decides``); :meth:`log_likelihoods` scores many parameter sets at once.
    """

    Params = OptionChoiceParams
    decides = "next_context"
    inputs = (
        Signal("values", "float64", ("n_contexts",), "each option's value"),
        Signal("context", "int64", (), "the option chosen at the previous trial (None on the first)"),
    )
    outputs = (
        Signal("action", "int64", (), "0 the previous choice repeated, 1 another option", initial=None,
               optional=True),
        Signal("next_context", "int64", (), "the option chosen at this trial", initial=None),
        LCRole.outputs[2],
    )
    probes = (
        Probe("action", "category", "", "engage: the previous choice repeated; disengage: another option",
              categories=("engage", "disengage")),
        Probe("next_context", "int", "index", "the option chosen at this trial"),
        Probe("p_chosen", "float", "probability", "probability of the chosen option"),
        GAIN_PROBE,
    )

    def reset(self, rng) -> None:
        self.rng = rng
        self._rec = (DISENGAGE, 0, 1.0, self.params.beta)

    def step(self, values, context):
        p = self.params
        beta = max(0.0, self.modulate(p.beta))
        previous = -1 if context is None else int(context)
        self._logp = option_log_probabilities(beta, values, previous, p.kappa, p.lapse)
        prob = np.exp(self._logp)
        choice = int(self.rng.choice(len(prob), p=prob))
        action = ENGAGE if choice == previous else DISENGAGE
        self.probabilities = tuple(prob)
        self._rec = (action, choice, float(prob[choice]), beta)
        return action, choice, beta

    def log_probability(self, decision: int) -> float:
        """log P(choose ``decision``) of this trial's draw, :func:`option_log_probabilities`."""
        return float(self._logp[decision])

    @classmethod
    def log_likelihoods(cls, params, inputs, decisions) -> np.ndarray:
        """(m, n) log P of the ``decisions`` of n trials for m parameter sets (``params``: name -> (m, 1)
        column; ``inputs``: name -> the n trials' values of that input)."""
        values = np.array(inputs["values"], dtype=np.float64)
        previous = np.array([-1 if c is None else c for c in inputs["context"]], dtype=np.int64)
        logp = option_log_probabilities(np.maximum(params["beta"], 0.0), values, previous, params["kappa"],
                                        params["lapse"])
        return logp[:, np.arange(len(decisions)), decisions]

    def record(self):
        return self._rec


@register("bandit.task")
class OptionTask(Region):
    """The clock of a choice task: each pass is one trial, a visit of the option the decision chose in
    the same pass (``choice``, not delayed), paid by the world of options. ``context`` is the chosen
    option, ``reward`` its outcome (the world's draw, or the recorded outcome in a replay)."""

    is_clock = True
    inputs = (Signal("choice", "int64", (), "the option chosen at this trial"),)
    outputs = (
        Signal("context", "int64", (), "the option chosen at this trial"),
        Signal("reward", "float64", (), "its outcome"),
    )
    probes = (
        Probe("context", "int", "index", "the option chosen at this trial"),
        Probe("n_frames", "int", "frames", "frames of the visit (1)"),
        Probe("reward", "float", "reward units", "the outcome of this trial's choice"),
    )

    def bind(self, world) -> None:
        if not isinstance(world, OptionsWorld):
            raise ValueError(f"{self.name}: bandit.task needs a world of options ([world] type = \"options\"); "
                             f"got {type(world).__name__}")
        self.world = world

    def reset(self, rng) -> None:
        self.world.begin()
        self.context, self.n_frames, self.reward = -1, 1, math.nan

    def step(self, choice):
        episode = self.world.step(int(choice))[0]
        self.context, self.reward = episode.context, float(episode.reward)
        return self.context, self.reward

    def record(self):
        return (self.context, self.n_frames, self.reward)
