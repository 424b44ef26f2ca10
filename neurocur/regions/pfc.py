"""PFC: the prefrontal value estimator — reward model (eq 14), transitions (eqs 12-13), LSPI."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, learner_param, param
from ..learn.lspi import LSPI
from .base import Probe, Region, Signal, register

ENGAGE, DISENGAGE = 0, 1
ACTIONS = ("engage", "disengage")


def transition_model(n_contexts: int) -> np.ndarray:
    """P[o, a, o'] of eqs 12-13: engage stays; disengage goes uniformly to another context."""
    P = np.empty((n_contexts, 2, n_contexts))
    P[:, ENGAGE] = np.eye(n_contexts)
    P[:, DISENGAGE] = (1.0 - np.eye(n_contexts)) / (n_contexts - 1)
    return P


def next_context(context: int, action: int, n_contexts: int, rng: np.random.Generator) -> int:
    """A draw from eqs 12-13's P[context, action, :]: engage stays; disengage goes to one of the
    other ``n_contexts - 1`` contexts, uniformly (one ``rng.integers`` draw)."""
    if action == ENGAGE:
        return int(context)
    k = int(rng.integers(n_contexts - 1))
    return k if k < context else k + 1


def reward_update(r, da, alpha):
    """Eq 14, one update of the reward model: ``R <- (1 - alpha) R + alpha * DA``.

    ``r`` is the current estimate, ``da`` the reward (dopamine) of the episode and ``alpha``
    the learning rate (:func:`eq14_rate`). Computed as ``r + alpha * (da - r)``, the same
    value in exact arithmetic; scalars or numpy arrays.
    """
    return r + alpha * (da - r)


#: ``PFC.alpha`` for eq 14 as a true sample average (the paper: "updated ... as a sample average")
SAMPLE_AVERAGE = "sample_average"


def eq14_rate(alpha, n):
    """Eq 14's learning rate for an estimate's ``n``-th sample (n >= 1): ``alpha`` itself (a
    constant rate, an exponential average of recent rewards), or ``1 / n`` for
    ``alpha = "sample_average"``, which makes the estimate the mean of all its samples."""
    return 1.0 / n if alpha == SAMPLE_AVERAGE else alpha


class RewardModel:
    """Eq 14's reward model ``R[o, a, o']`` (previous context, decision, context) and the expected
    reward ``R(o, a) = sum_o' P[o, a, o'] R[o, a, o']`` under eqs 12-13's ``P``; every estimate
    starts at 0. The PFC holds one; :mod:`neurocur.analysis.stats.reward_model` replays one from a run's
    recorded DA and decisions."""

    def __init__(self, n_contexts: int, alpha) -> None:
        self.alpha = alpha
        self.P = transition_model(n_contexts)
        self.R3 = np.zeros((n_contexts, 2, n_contexts))
        self.N3 = np.zeros((n_contexts, 2, n_contexts), dtype=np.int64)  # samples of each estimate

    def update(self, o: int, a: int, o_next: int, da: float) -> bool:
        """Eq 14 on ``R[o, a, o_next]`` with the reward ``da``; True when the estimate changed."""
        self.N3[o, a, o_next] += 1
        r = self.R3[o, a, o_next]
        new = reward_update(r, da, eq14_rate(self.alpha, self.N3[o, a, o_next]))
        self.R3[o, a, o_next] = new
        return bool(new != r)

    def expected(self) -> np.ndarray:
        """``R(o, a)``, (n_contexts, 2)."""
        return np.einsum("oas,oas->oa", self.P, self.R3)


@dataclass(frozen=True)
class PFCParams:
    alpha: float | str = param(0.2, float, low=0.0, high=1.0, low_open=True, choices=(SAMPLE_AVERAGE,),
                               doc='eq 14 learning rate, or "sample_average" (1/n for an estimate\'s n-th sample)')
    discount: float = learner_param(LSPI, "discount", 0.9, doc="LSPI discount factor")

    def __post_init__(self):
        check_params(self)


@register("pfc.lspi")
class PFCLSPI(Region):
    """Model-based values of engaging or disengaging in each context (sections 2.7-2.8).

    Step (the paper updates the reward model and the policy after every episode, before
    the next decision): with the previous context ``o``, the previous action ``a``
    (delayed edge from LC) and the current context ``o'``, eq 14
    ``R[o, a, o'] <- (1 - alpha) R[o, a, o'] + alpha * DA``; then the expected reward
    ``R(o, a) = sum_o' P[o, a, o'] R[o, a, o']`` and model-based LSPI on (P, R), warm-started from the previous policy, give
    ``Q``; output ``Q[o']`` = (Q_engage, Q_disengage) of the current context.
    """

    Params = PFCParams
    inputs = (
        Signal("context", "int64", ()),
        Signal("da", "float64", ()),
        Signal("action", "int64", (), "previous decision (0 engage, 1 disengage)"),
    )
    outputs = (Signal("q", "float64", (2,), "(Q_engage, Q_disengage) of the current context"),)
    probes = (
        Probe("q_engage", "float", "discounted DA", "Q(current context, engage)"),
        Probe("q_disengage", "float", "discounted DA", "Q(current context, disengage)"),
    )

    def bind(self, world) -> None:
        if world.n_contexts < 2:
            raise ValueError(f"{self.name}: engage/disengage needs at least 2 contexts; got {world.n_contexts}")
        self.n_contexts = world.n_contexts

    def reset(self, rng) -> None:
        n = self.n_contexts
        self.model = RewardModel(n, self.params.alpha)
        self.planner = LSPI(self.model.P, self.params.discount)
        self.Q = np.zeros((n, 2))
        self.policy = None
        self.previous_context = None
        self.q = self.Q[0].copy()

    def step(self, context, da, action):
        if self.previous_context is not None and action is not None:
            if self.model.update(self.previous_context, action, context, da):  # an unchanged model keeps its Q
                self.Q, self.policy = self.planner.solve(self.model.expected(), self.policy)
        self.previous_context = context
        self.q = self.Q[context].copy()
        return (self.q,)

    def record(self):
        return (self.q[ENGAGE], self.q[DISENGAGE])
