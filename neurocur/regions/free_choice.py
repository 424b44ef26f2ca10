"""Regions of a free-choice learning task: a per-episode error from practice or from a recording,
and per-context values.

Not in the paper. They make a circuit for the free-choice tasks of Ten, Kaushik, Oudeyer &
Gottlieb (2021, Nat Commun 12:4432), where a learner picks among tasks of graded difficulty:

- ``signal.practice`` simulates the error of a learner who practises each task (the error
  falls exponentially with the number of visits, more slowly on a harder task);
- ``signal.recorded`` emits a recorded per-episode error instead (signal replay of human or
  animal data, :mod:`neurocur.fit.replay`), in place of HPC or of ``signal.practice``
  (``Circuit.replace``);
- ``choice.values`` keeps one value per context, eq 14's update of the dopamine of
  its visits, for the choice of :mod:`.lc_choice`.

The two signal regions have HPC's outputs that VTA reads (``reward_error``, ``familiar``,
``module_learned``), so a VTA model reads them unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register
from .pfc import SAMPLE_AVERAGE, eq14_rate, reward_update

SIGNAL_OUTPUTS = (
    Signal("reward_error", "float64", (), "the episode's error"),
    Signal("familiar", "bool", (), "always False: no stored module gates a task"),
    Signal("module_learned", "bool", (), "always False"),
)
SIGNAL_PROBES = (Probe("error", "float", "error units", "the episode's error"),)


@dataclass(frozen=True)
class PracticeParams:
    rate: float = param(0.3, float, low=0.0, doc="learning rate of the easiest task (1 / visits)")
    spread: float = param(3.0, float, low=1.0, doc="each harder task learns this many times more slowly")
    impossible_last: bool = param(True, bool, doc="the last task cannot be learned (its error stays at 1)")
    noise: float = param(0.02, float, low=0.0, doc="s.d. of the Gaussian noise on each episode's error")

    def __post_init__(self):
        check_params(self)


@register("signal.practice")
class PracticeSignal(Region):
    """Error of task k after its n-th visit: exp(-rate_k n) + noise, rate_k = rate / spread**k
    (0 for the last task with ``impossible_last``): tasks of graded difficulty."""

    Params = PracticeParams
    inputs = (Signal("episode", "Episode", (), "the visit (its context)"),)
    outputs = SIGNAL_OUTPUTS
    probes = SIGNAL_PROBES

    def bind(self, world) -> None:
        n, p = world.n_contexts, self.params
        self.rates = p.rate / p.spread ** np.arange(n)
        if p.impossible_last:
            self.rates[-1] = 0.0

    def reset(self, rng) -> None:
        self.rng = rng
        self.visits = np.zeros(len(self.rates), dtype=np.int64)
        self.error = math.nan

    def step(self, episode):
        context = episode.context
        self.visits[context] += 1
        self.error = float(math.exp(-self.rates[context] * self.visits[context])
                           + self.params.noise * self.rng.standard_normal())
        return self.error, False, False

    def record(self):
        return (self.error,)


@register("signal.recorded")
class RecordedSignal(Region):
    """Emits a recorded error, one value per episode in order (``series``, given in Python:
    ``RecordedSignal("HPC", series=errors)``); a run longer than the recording is an error."""

    inputs = (Signal("episode", "Episode", (), "the visit (its context)"),)
    outputs = SIGNAL_OUTPUTS
    probes = SIGNAL_PROBES

    def __init__(self, name: str = "", params=None, *, series=(), **kwargs):
        super().__init__(name, params, **kwargs)
        self.series = np.asarray(series, dtype=np.float64)

    def reset(self, rng) -> None:
        self.t = 0
        self.error = math.nan

    def step(self, episode):
        if self.t >= len(self.series):
            raise ValueError(f"{self.name}: the recording has {len(self.series)} episodes; the run asked for more")
        self.error = float(self.series[self.t])
        self.t += 1
        return self.error, False, False

    def record(self):
        return (self.error,)


@dataclass(frozen=True)
class ContextValuesParams:
    alpha: float | str = param(0.2, float, low=0.0, high=1.0, low_open=True, choices=(SAMPLE_AVERAGE,),
                               doc='eq 14 learning rate, or "sample_average" (1/n for a context\'s n-th visit)')

    def __post_init__(self):
        check_params(self)


@register("choice.values")
class ContextValues(Region):
    """One value per context: at each visit of context o, eq 14 ``V[o] <- V[o] + alpha (DA - V[o])``
    (:func:`~neurocur.regions.pfc.reward_update`); values start at 0. Outputs all values."""

    Params = ContextValuesParams
    inputs = (Signal("context", "int64", ()), Signal("da", "float64", ()))
    outputs = (Signal("values", "float64", ("n_contexts",), "value of each context"),)
    probes = (Probe("value", "float", "DA units", "value of the current context after this episode"),)

    def bind(self, world) -> None:
        self.n_contexts = world.n_contexts

    def reset(self, rng) -> None:
        self.values = np.zeros(self.n_contexts)
        self.visits = np.zeros(self.n_contexts, dtype=np.int64)
        self.context = 0

    def step(self, context, da):
        self.visits[context] += 1
        rate = eq14_rate(self.params.alpha, self.visits[context])
        self.values[context] = reward_update(self.values[context], da, rate)
        self.context = context
        return (self.values.copy(),)

    def record(self):
        return (self.values[self.context],)
