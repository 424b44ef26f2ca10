"""LC variant: a softmax engage/disengage decision whose inverse temperature is the NE gain.

Not in the paper (its LC is :mod:`.lc`'s epsilon-greedy rule). The gain reading of
noradrenaline follows Aston-Jones & Cohen (2005, Annu Rev Neurosci 28:403): NE scales
the gain of the decision, so a high gain exploits the value difference and a low gain
explores. This is also the worked example of ``docs/extending.md``: a new LC model is
this file, a circuit file (``neurocur/circuits/lc_softmax.toml``) and a test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..config import check_params, param
from .base import Probe, register
from .lc import DECISION_PROBES, LCRole, phasic_ne
from .pfc import DISENGAGE, ENGAGE, next_context


@dataclass(frozen=True)
class SoftmaxLCParams:
    gain: float = param(1.0, float, low=0.0, doc="beta, inverse temperature of the decision (1 / DA units)")

    def __post_init__(self):
        check_params(self)


@register("lc.softmax")
class SoftmaxLC(LCRole):
    """P(disengage) = sigma(gain * (Q_dis - Q_eng)), sigma the logistic function.

    Per pass the action is drawn with that probability (one ``rng.random`` draw), then
    the next context as in eq 13 (:func:`~neurocur.regions.pfc.next_context`).
    ``gain = 0`` switches at random, a large gain is greedy. NE, as for the
    epsilon-greedy LC: tonic NE = P(disengage | Q, gain); phasic NE as
    :func:`~neurocur.regions.lc.phasic_ne`. The ports are the LC role's (:class:`LCRole`).
    """

    Params = SoftmaxLCParams
    probes = (
        *DECISION_PROBES,
        Probe("ne_tonic", "float", "probability", "P(disengage | Q, gain)"),
        Probe("ne_phasic", "float", "[0, 1]", "event-locked burst (1 at module storage, engage advantage)"),
    )

    def reset(self, rng) -> None:
        self.rng = rng
        self._rec = (ENGAGE, 0, 0.5, 0.0)

    def step(self, context, q, module_learned):
        advantage = float(q[DISENGAGE]) - float(q[ENGAGE])
        tonic = 0.5 * (1.0 + math.tanh(0.5 * self.params.gain * advantage))  # the logistic, overflow-free
        action = DISENGAGE if self.rng.random() < tonic else ENGAGE
        nxt = next_context(context, action, self.n_contexts, self.rng)
        phasic = phasic_ne(action, module_learned, float(q[ENGAGE]), float(q[DISENGAGE]))
        self._rec = (action, nxt, tonic, phasic)
        return action, nxt

    def record(self):
        return self._rec
