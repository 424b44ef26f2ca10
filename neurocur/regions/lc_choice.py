"""LC variant for free-choice tasks: a softmax choice among N contexts over per-context values.

Not in the paper (its agent decides engage or disengage, section 2.8). In a free-choice
learning task (Ten, Kaushik, Oudeyer & Gottlieb 2021, Nat Commun 12:4432) the agent picks
the next task among all of them; the choice is a softmax over each task's value with the
NE gain as inverse temperature (the gain reading of Aston-Jones & Cohen 2005, as in
:mod:`.lc_softmax`), and an optional stickiness bonus for the current task.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

from ..config import check_params, param
from .base import Probe, Signal, register
from .lc import LCRole
from .lc_softmax import GAIN_PROBE
from .pfc import DISENGAGE, ENGAGE


@dataclass(frozen=True)
class ChoiceLCParams:
    gain: float = param(5.0, float, low=0.0, doc="beta, inverse temperature of the choice (1 / value units)")
    stay: float = param(0.0, float, doc="bonus added to the current context's value before the softmax (value units)")

    def __post_init__(self):
        check_params(self)


def choice_probabilities(gain, values, context, stay):
    """P(choose k) = exp(gain (V_k + stay [k = context])) / sum_j exp(gain (V_j + stay [j = context])).

    ``values``: (..., n) per-context values; ``gain`` broadcasts against its leading axes.
    Computed with the maximum subtracted (no overflow)."""
    v = np.array(values, dtype=np.float64)
    v[..., context] += stay
    z = np.multiply(np.asarray(gain, dtype=np.float64)[..., None], v)
    z -= z.max(axis=-1, keepdims=True)
    e = np.exp(z)
    return e / e.sum(axis=-1, keepdims=True)


def choice_log_probabilities(gain, values, context, stay):
    """log P(choose k), :func:`choice_probabilities` as a log-softmax (scipy's ``log_softmax``: a context
    far below the best keeps its large negative log-probability instead of log 0). Broadcasts: ``values``
    (..., n), ``context`` over its leading axes (one current context per row), ``gain`` and ``stay``
    against them (e.g. a column of thetas against a row of episodes)."""
    v = np.asarray(values, dtype=np.float64)
    current = np.arange(v.shape[-1]) == np.asarray(context)[..., None]
    bonus = np.asarray(stay, dtype=np.float64)[..., None] * current
    return special.log_softmax(np.asarray(gain, dtype=np.float64)[..., None] * (v + bonus), axis=-1)


@register("choice.softmax")
class ChoiceLC(LCRole):
    """A softmax choice of the next context among all N (:func:`choice_probabilities`).

    Reads the current context and ``values`` (one per context, e.g. from
    ``choice.values``); draws the next context (one ``rng.choice``); ``action`` is
    engage when it is the current context, disengage otherwise. The NE level is the gain,
    released through the drugs (clipped at 0); ``ne_gain`` records it. The scored decision
    (``decides``) is the chosen context, and :attr:`probabilities` holds P(choose k) for every k.
    """

    Params = ChoiceLCParams
    decides = "next_context"
    inputs = (
        Signal("context", "int64", ()),
        Signal("values", "float64", ("n_contexts",), "value of choosing each context"),
    )
    outputs = (
        Signal("action", "int64", (), "0 stay (the chosen context is the current one), 1 leave", initial=None,
               optional=True),
        *LCRole.outputs[1:],
    )
    probes = (
        Probe("action", "category", "", "engage (stay) or disengage (leave) at the end of this episode",
              categories=("engage", "disengage")),
        Probe("next_context", "int", "index", "context chosen for the next episode"),
        Probe("p_chosen", "float", "probability", "probability of the chosen context"),
        GAIN_PROBE,
    )

    def reset(self, rng) -> None:
        self.rng = rng
        self._rec = (ENGAGE, 0, 1.0, self.params.gain)

    def step(self, context, values):
        gain = max(0.0, self.modulate(self.params.gain))
        p = choice_probabilities(gain, values, int(context), self.params.stay)
        nxt = int(self.rng.choice(len(p), p=p))
        action = ENGAGE if nxt == context else DISENGAGE
        self.probabilities = tuple(p)
        self._choice = (gain, values, int(context))
        self._rec = (action, nxt, float(p[nxt]), gain)
        return action, nxt, gain

    def log_probability(self, decision: int) -> float:
        """log P(choose ``decision``) of this pass's draw, :func:`choice_log_probabilities`."""
        gain, values, context = self._choice
        return float(choice_log_probabilities(gain, values, context, self.params.stay)[decision])

    @classmethod
    def log_likelihoods(cls, params, inputs, decisions) -> np.ndarray:
        """(m, n) log softmax of n chosen contexts for m parameter sets at once (:func:`choice_log_probabilities`;
        the protocol of :attr:`~neurocur.regions.lc.LCRole.log_likelihoods`)."""
        values = np.array(inputs["values"], dtype=np.float64)
        contexts = np.array(inputs["context"])
        logp = choice_log_probabilities(np.maximum(params["gain"], 0.0), values, contexts, params["stay"])
        return logp[:, np.arange(len(contexts)), decisions]

    def record(self):
        return self._rec
