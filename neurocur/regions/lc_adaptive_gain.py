"""LC variant: adaptive gain theory, the LC mode set by utility on two timescales.

Not in the paper (its LC is :mod:`.lc`'s epsilon-greedy rule). Aston-Jones & Cohen (2005,
Annu Rev Neurosci 28:403, section "Utility-based control of LC mode") propose that the LC
integrates the utility of the current task on a short and a long timescale: when both
are high it stays in the phasic mode (high gain: exploit, stay engaged); when utility
falls, in particular the short-term utility below the long-term one, it moves to the
tonic mode (low gain: explore, disengage). Their combination,
engagement = [1 - logistic(disengagement)] x logistic(long-term utility), is read here with the
disengagement l - s, the long-term minus the short-term utility. That is a different rule from
PsyNeuLink's DualAdaptiveIntegrator (the function of its AGTControlMechanism, the Cohen lab's
implementation), whose PRODUCT is [1 - logistic(g_s s - b_s)] x logistic(g_l l - b_l), the first
factor of the short-term average alone, falling as it rises; and whose code updates each average
as (1 - previous) x rate + previous x input (the arguments of its EWMA filter swapped), not
previous + rate x (input - previous) (docs/validation.md, section 2;
tests/regions/test_gilzenrat_reference.py).
Here the utility is the dopamine the LC receives (learning progress, with VTA's boredom
value on familiar episodes), and the gain is the inverse temperature of the softmax
decision of :mod:`.lc_softmax`.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..config import ConfigError, check_params, param
from .base import Probe, Signal, register
from .lc import DECISION_PROBES, phasic_ne
from .lc_softmax import GAIN_PROBE, GainLC, logistic
from .pfc import DISENGAGE, ENGAGE


@dataclass(frozen=True)
class AdaptiveGainLCParams:
    tau_short: float = param(5.0, float, low=1.0, doc="time constant of the short-term utility average (episodes)")
    tau_long: float = param(50.0, float, low=1.0, doc="time constant of the long-term utility average (episodes)")
    slope_short: float = param(1.0, float, low=0.0, low_open=True,
                               doc="slope of the disengagement logistic on long - short utility (1 / DA units)")
    slope_long: float = param(1.0, float, low=0.0, low_open=True,
                              doc="slope of the long-term utility logistic (1 / DA units)")
    utility_mid: float = param(0.0, float, doc="long-term utility at which its logistic is 1/2 (DA units)")
    gain_tonic: float = param(0.5, float, low=0.0, doc="gain in the full tonic mode, engagement 0 (1 / DA units)")
    gain_phasic: float = param(10.0, float, low=0.0, doc="gain in the full phasic mode, engagement 1 (1 / DA units)")

    def __post_init__(self):
        check_params(self)
        if self.tau_long <= self.tau_short:
            raise ConfigError(type(self).__name__, "tau_long", f"more than tau_short = {self.tau_short}",
                              repr(self.tau_long))
        if self.gain_phasic < self.gain_tonic:
            raise ConfigError(type(self).__name__, "gain_phasic", f"at least gain_tonic = {self.gain_tonic}",
                              repr(self.gain_phasic))


@register("lc.adaptive_gain")
class AdaptiveGainLC(GainLC):
    """The LC mode from utility on two timescales (Aston-Jones & Cohen 2005); the mode sets the gain.

    Per pass, with u the dopamine of this episode (input ``da``, wired from VTA in
    ``neurocur/circuits/lc_adaptive_gain.toml``):

    - short- and long-term utility, leaky averages with time constants in episodes
      (both start at 0): s <- s + (u - s) / tau_short, l <- l + (u - l) / tau_long;
    - engagement E = [1 - sigma(slope_short (l - s))] x sigma(slope_long (l - utility_mid)),
      sigma the logistic: high when the short-term utility is at or above the long-term
      one and the long-term utility is high (phasic mode), near 0 when utility falls
      (tonic mode);
    - gain = gain_tonic + (gain_phasic - gain_tonic) E, released through the drugs, then the
      softmax decision of :class:`~neurocur.regions.lc_softmax.GainLC`.

    NE: the released level is the gain (``ne_gain``, output ``ne``). Tonic NE is the LC's
    state, the tonic-mode drive ``ne_tonic = 1 - E`` in [0, 1]; phasic NE is the burst of
    :func:`~neurocur.regions.lc.phasic_ne` scaled by the engagement, ``ne_phasic = E x
    phasic_ne``: bursts to the task in the phasic mode, weak ones in the tonic mode. A drug
    acts on the released gain, not on the mode, so it leaves ``ne_tonic`` and the
    utilities unchanged.
    """

    Params = AdaptiveGainLCParams
    inputs = (*GainLC.inputs, Signal("da", "float64", (), "utility of this episode: the dopamine from VTA"))
    probes = (
        *DECISION_PROBES,
        Probe("ne_tonic", "float", "[0, 1]", "tonic-mode drive, 1 - engagement"),
        Probe("ne_phasic", "float", "[0, 1]", "engagement x event-locked burst (module storage, engage advantage)"),
        GAIN_PROBE,
        Probe("utility_short", "float", "DA units", "short-term (tau_short) average of the dopamine"),
        Probe("utility_long", "float", "DA units", "long-term (tau_long) average of the dopamine"),
    )

    def reset(self, rng) -> None:
        self.rng = rng
        self.short = self.long = 0.0
        p = self.params
        e0 = self.engagement()
        self._rec = (ENGAGE, 0, 1.0 - e0, 0.0, p.gain_tonic + (p.gain_phasic - p.gain_tonic) * e0, 0.0, 0.0)

    def engagement(self) -> float:
        """E = [1 - sigma(slope_short (l - s))] x sigma(slope_long (l - utility_mid)), in [0, 1]."""
        p = self.params
        return (1.0 - logistic(self.long - self.short, p.slope_short)) * logistic(self.long - p.utility_mid, p.slope_long)

    def step(self, context, q, module_learned, da):
        p = self.params
        self.short += (da - self.short) / p.tau_short
        self.long += (da - self.long) / p.tau_long
        e = self.engagement()
        gain, _, action, nxt = self.decide(p.gain_tonic + (p.gain_phasic - p.gain_tonic) * e, context, q)
        phasic = e * phasic_ne(action, module_learned, float(q[ENGAGE]), float(q[DISENGAGE]))
        self._rec = (action, nxt, 1.0 - e, phasic, gain, self.short, self.long)
        return action, nxt, gain

    def record(self):
        return self._rec
