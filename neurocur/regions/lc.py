"""LC: locus coeruleus — the engage/disengage decision and tonic/phasic norepinephrine."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from ..config import check_params, param
from .base import Probe, Region, Signal, register
from .pfc import ACTIONS, DISENGAGE, ENGAGE, next_context


@dataclass(frozen=True)
class LCParams:
    epsilon0: float = param(0.6, float, low=0.0, high=1.0, doc="epsilon after reset")
    decay: float = param(0.995, float, low=0.0, high=1.0, low_open=True, doc="epsilon factor per episode")

    def __post_init__(self):
        check_params(self)


class LCRole(Region):
    """The LC role's ports, shared by every LC model: reads the context, Q (engage, disengage)
    and the module-learned event; decides the action and the next context (eq 13); records
    the decision and tonic and phasic NE (:data:`DECISION_PROBES` first).

    Every LC model releases noradrenaline (``modulator = "ne"``): the level its decision
    reads passes through :meth:`~neurocur.regions.base.Region.modulate` first, so a drug
    lesion (clamp, scale, noise) changes behaviour. The released level is also the
    optional output ``ne``, for a region that a circuit wires to it. What the level is
    differs by model (docs/regions.md, "LC"): P(disengage) for the epsilon-greedy rule,
    the gain of the decision (1 / DA units) for the others.
    """

    modulator = "ne"
    #: Whether P(decision | state, theta) is a closed-form function of the parameters given the
    #: replayed inputs (:mod:`neurocur.fit.replay` evaluates it for many theta from one replay).
    closed_form: ClassVar[bool] = True
    #: The output whose value is the observed decision a replay scores: ``"action"`` (engage 0,
    #: disengage 1) here, the chosen context for a free choice (:mod:`.lc_choice`).
    decides: ClassVar[str] = "action"
    #: ``(P(engage), P(disengage))`` that this pass's draw used, set by every ``step``: the
    #: likelihood of each decision given the region's state, its inputs and its parameters (a
    #: drug's noise included: under a noise drug it is conditional on the drawn level).
    probabilities: tuple[float, float] = (0.5, 0.5)
    #: ``log_likelihoods(params, inputs, decisions) -> (m, n) array``, a classmethod of a model whose
    #: log P(decision) is a closed form it can evaluate for many parameter sets at once: ``params`` maps
    #: each of its parameters to an (m, 1) column (one row per parameter set), ``inputs`` each of its
    #: inputs to the n passes' values, ``decisions`` the n scored decisions. A replay
    #: (:mod:`neurocur.fit.replay`) calls it instead of stepping the region once per parameter set;
    #: None (the default): the replay steps it.
    log_likelihoods: ClassVar = None
    inputs = (
        Signal("context", "int64", ()),
        Signal("q", "float64", (2,)),
        Signal("module_learned", "bool", ()),
    )
    outputs = (
        Signal("action", "int64", (), "0 engage, 1 disengage", initial=None),
        Signal("next_context", "int64", (), "context of the next episode", initial=None),
        Signal("ne", "float64", (), "the released NE level the decision read (after drugs)", optional=True),
    )

    def bind(self, world) -> None:
        if world.n_contexts < 2:
            raise ValueError(f"{self.name}: engage/disengage needs at least 2 contexts; got {world.n_contexts}")
        self.n_contexts = world.n_contexts

    def log_probability(self, decision: int) -> float:
        """log P(``decision`` | state, theta) of this pass's draw (:attr:`probabilities`): -inf for a
        decision the draw gave probability 0. The softmax models compute it without underflow."""
        p = self.probabilities[decision]
        return math.log(p) if p > 0 else -math.inf


#: The decision's probes, recorded first by every LC model.
DECISION_PROBES = (
    Probe("action", "category", "", "decision at the end of this episode", categories=ACTIONS),
    Probe("next_context", "int", "index", "context of the next episode"),
)


def phasic_ne(action: int, module_learned: bool, q_engage: float, q_disengage: float) -> float:
    """Phasic NE: 1 at a module-learned event; else, on an engage decision, the burst that
    commits to the task, max(0, tanh(Q_eng - Q_dis)); else 0."""
    if module_learned:
        return 1.0
    if action == ENGAGE:
        return max(0.0, math.tanh(q_engage - q_disengage))
    return 0.0


@register("lc.epsilon_greedy")
class EpsilonGreedyLC(LCRole):
    """Decaying epsilon-greedy engage/disengage (section 2.8.1) with NE read-outs.

    Per pass: on a module-learned event epsilon is reset to ``epsilon0``; with
    probability epsilon the action is drawn uniformly from {engage, disengage},
    otherwise it is ``argmax Q`` (a tie is broken uniformly); then epsilon is
    multiplied by ``decay``. Engage stays in the context; disengage draws the next
    context uniformly from the others (eq 13, :func:`~neurocur.regions.pfc.next_context`).
    The recorded ``epsilon`` is the one used.

    NE, with g = 1 if Q_dis > Q_eng, 1/2 on a tie, 0 otherwise:

    - tonic NE = P(disengage | Q, epsilon) = epsilon/2 + (1 - epsilon) g, in [0, 1]: the
      current drive to disengage, high when exploring or when staying is not worth it;
    - phasic NE = 1 at a module-learned event; else, on an engage decision,
      max(0, tanh(Q_eng - Q_dis)) (the burst that commits to the task, growing with
      the advantage of staying); else 0.

    The released NE level is tonic NE, P(disengage). Without a drug the draw is the
    paper's (an epsilon coin, then a uniform or the greedy action), which realises that
    probability exactly; under a drug (:meth:`~neurocur.regions.base.Region.modulate`)
    the drugged level, clipped to [0, 1], is drawn against once, and is what ``ne_tonic``
    records and ``ne`` emits.

    Lesion ``random``: epsilon = 1 forever, so contexts switch at random (section 4.3).
    """

    Params = LCParams
    probes = (
        *DECISION_PROBES,
        Probe("epsilon", "float", "probability", "exploration rate used for this decision"),
        Probe("ne_tonic", "float", "probability", "P(disengage | Q, epsilon)"),
        Probe("ne_phasic", "float", "[0, 1]", "event-locked burst (1 at module storage, engage advantage)"),
    )
    lesions = {"random": {"epsilon0": 1.0, "decay": 1.0}}

    def reset(self, rng) -> None:
        self.rng = rng
        self.epsilon = self.params.epsilon0
        self._rec = (ENGAGE, 0, self.epsilon, 0.5, 0.0)

    def step(self, context, q, module_learned):
        rng = self.rng
        if module_learned:
            self.epsilon = self.params.epsilon0
        eps = self.epsilon
        q_eng, q_dis = float(q[ENGAGE]), float(q[DISENGAGE])
        g = 1.0 if q_dis > q_eng else (0.5 if q_dis == q_eng else 0.0)
        tonic = self.modulate(0.5 * eps + (1.0 - eps) * g)
        if self.drugs:
            tonic = min(1.0, max(0.0, tonic))
            action = DISENGAGE if rng.random() < tonic else ENGAGE
        elif rng.random() < eps or g == 0.5:
            action = int(rng.integers(2))
        else:
            action = DISENGAGE if g == 1.0 else ENGAGE
        nxt = next_context(context, action, self.n_contexts, rng)
        phasic = phasic_ne(action, module_learned, q_eng, q_dis)
        self.epsilon = eps * self.params.decay
        self.probabilities = (1.0 - tonic, tonic)
        self._rec = (action, nxt, eps, tonic, phasic)
        return action, nxt, tonic

    def record(self):
        return self._rec
