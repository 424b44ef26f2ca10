"""LC variant: a softmax engage/disengage decision whose inverse temperature is the NE gain.

Not in the paper (its LC is :mod:`.lc`'s epsilon-greedy rule). The gain reading of
noradrenaline follows Aston-Jones & Cohen (2005, Annu Rev Neurosci 28:403): NE scales
the gain of the decision, so a high gain exploits the value difference and a low gain
explores. This is also the worked example of ``docs/extending.md``: a new LC model is
this file, a circuit file (``neurocur/circuits/lc_softmax.toml``) and a test.

:class:`GainLC` is the decision every gain model shares (this one, the adaptive-gain LC of
:mod:`.lc_adaptive_gain` and the FitzHugh-Nagumo LC of :mod:`.lc_fhn`): each computes its
gain, and the decision releases it through the drugs and draws the action.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from ..config import check_params, param
from .base import Probe, register
from .lc import DECISION_PROBES, LCRole, phasic_ne
from .pfc import DISENGAGE, ENGAGE, next_context

#: The released gain, recorded by every gain model after its NE probes.
GAIN_PROBE = Probe("ne_gain", "float", "1 / DA", "released NE gain (after drugs): the decision's inverse temperature")


def logistic(x: float, slope: float = 1.0) -> float:
    """sigma(slope * x) = 1 / (1 + exp(-slope * x)), computed overflow-free as (1 + tanh(slope * x / 2)) / 2."""
    return 0.5 * (1.0 + math.tanh(0.5 * slope * x))


def log_p_decision(gain, dq, decision):
    """log P(``decision`` | Q, gain) = log sigma(+-gain * dq), dq = Q_dis - Q_eng, + for disengage (1)
    and - for engage (0); numpy arrays broadcast (e.g. a column of gains against a row of episodes,
    :mod:`neurocur.fit`). Computed by scipy's ``log_expit``, so a decision far out in the tail gets its
    large negative log-probability, not the -inf of a probability rounded to 0."""
    sign = np.where(np.asarray(decision) == DISENGAGE, 1.0, -1.0)
    return special.log_expit(sign * np.multiply(gain, dq))


def p_disengage(gain: float, q) -> float:
    """P(disengage | Q, gain) = sigma(gain * (Q_dis - Q_eng)), sigma the logistic function."""
    return logistic(float(q[DISENGAGE]) - float(q[ENGAGE]), gain)


class GainLC(LCRole):
    """An LC whose NE level is the gain of a softmax decision (the LC role's ports)."""

    def decide(self, gain: float, context, q) -> tuple[float, float, int, int]:
        """Release ``gain`` (:meth:`~neurocur.regions.base.Region.modulate`, then clipped at 0:
        a released level is never negative), draw the action with P(disengage) =
        :func:`p_disengage` (one ``rng.random`` draw) and the next context (eq 13,
        :func:`~neurocur.regions.pfc.next_context`). Returns (released gain, P(disengage),
        action, next context)."""
        gain = max(0.0, self.modulate(gain))
        p = p_disengage(gain, q)
        self.probabilities = (1.0 - p, p)
        self._gain_dq = (gain, float(q[DISENGAGE]) - float(q[ENGAGE]))
        action = DISENGAGE if self.rng.random() < p else ENGAGE
        return gain, p, action, next_context(context, action, self.n_contexts, self.rng)

    def log_probability(self, decision: int) -> float:
        """log P(``decision``) of this pass's draw, :func:`log_p_decision` (no underflow in the tails)."""
        return float(log_p_decision(*self._gain_dq, decision))


@dataclass(frozen=True)
class SoftmaxLCParams:
    gain: float = param(1.0, float, low=0.0, doc="beta, inverse temperature of the decision (1 / DA units)")

    def __post_init__(self):
        check_params(self)


@register("lc.softmax")
class SoftmaxLC(GainLC):
    """P(disengage) = sigma(gain * (Q_dis - Q_eng)), sigma the logistic function.

    Per pass the action is drawn with that probability (one ``rng.random`` draw), then
    the next context as in eq 13 (:func:`~neurocur.regions.pfc.next_context`).
    ``gain = 0`` switches at random, a large gain is greedy. The NE level is the gain:
    a drug acts on it, ``ne_gain`` records and ``ne`` emits the released gain. Tonic NE =
    P(disengage | Q, released gain); phasic NE as :func:`~neurocur.regions.lc.phasic_ne`.
    The ports are the LC role's (:class:`~neurocur.regions.lc.LCRole`).
    """

    Params = SoftmaxLCParams
    probes = (
        *DECISION_PROBES,
        Probe("ne_tonic", "float", "probability", "P(disengage | Q, gain)"),
        Probe("ne_phasic", "float", "[0, 1]", "event-locked burst (1 at module storage, engage advantage)"),
        GAIN_PROBE,
    )

    def reset(self, rng) -> None:
        self.rng = rng
        self._rec = (ENGAGE, 0, 0.5, 0.0, self.params.gain)

    def step(self, context, q, module_learned):
        gain, tonic, action, nxt = self.decide(self.params.gain, context, q)
        phasic = phasic_ne(action, module_learned, float(q[ENGAGE]), float(q[DISENGAGE]))
        self._rec = (action, nxt, tonic, phasic, gain)
        return action, nxt, gain

    @classmethod
    def log_likelihoods(cls, params, inputs, decisions) -> np.ndarray:
        """(m, n) log sigma(+-gain (Q_dis - Q_eng)) of n decisions for m gains at once (:func:`log_p_decision`;
        the protocol of :attr:`~neurocur.regions.lc.LCRole.log_likelihoods`)."""
        q = np.array(inputs["q"], dtype=np.float64)
        return log_p_decision(np.maximum(params["gain"], 0.0), q[:, DISENGAGE] - q[:, ENGAGE], decisions)

    def record(self):
        return self._rec
