"""LC variant: the LC population as a FitzHugh-Nagumo unit whose release sets the decision's gain.

Not in the paper (its LC is :mod:`.lc`'s epsilon-greedy rule). The reduced LC model of
Gilzenrat, Holmes, Rajkowski, Aston-Jones & Cohen (2002, Neural Networks 15:647), the
mean-field of the coupled LC units of Usher et al. (1999, Science 283:549), is a
FitzHugh-Nagumo system with activation v and recovery u:

    tau_v dv/dt = v (alpha - v)(v - 1) - u + x(t) + sigma xi(t)
    tau_u du/dt = h(v) - u,     h(v) = C v + (1 - C) d

The mode parameter C (their electrotonic coupling) sets the mode: C = 1 is the phasic
mode (v rests at 0 and an input drives a burst, then refractoriness); lowering C moves
the recovery towards the constant d and the rest point up the v-nullcline, so the
baseline firing rises and the evoked burst shrinks (the tonic mode). xi is white noise
(their LC units are noisy); without it the phasic mode rests exactly at v = 0 and the
baseline is flat. The LC's output gain is g = G + k v (their eq for the gain of the decision units); here v is read as a
firing rate, clipped to [0, 1], and averaged over the decision window (the NE released
during it). The gain is the inverse temperature of the softmax decision of
:mod:`.lc_softmax`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..config import ConfigError, check_params, param
from .base import Probe, register
from .lc import DECISION_PROBES, phasic_ne
from .lc_softmax import GAIN_PROBE, GainLC
from .pfc import DISENGAGE, ENGAGE


@dataclass(frozen=True)
class FHNUnitParams:
    """The FitzHugh-Nagumo unit's parameters (Gilzenrat et al. 2002) of the LC over an episode's
    sub-steps (:class:`FHNLCParams`). Gilzenrat et al.'s own model of their task, with their
    parameters, is :mod:`.lc_gilzenrat`."""

    mode: float = param(1.0, float, low=0.0, high=1.0, doc="C: 1 phasic mode, lower values tonic mode")
    baseline: float = param(-0.5, float, doc="d, the recovery's level as C falls (a.u. of v)")
    alpha: float = param(0.5, float, low=0.0, high=1.0, low_open=True, high_open=True,
                         doc="threshold of the cubic v (alpha - v)(v - 1) (a.u. of v)")
    tau_v: float = param(0.05, float, low=0.0, low_open=True, doc="time constant of the activation (time units)")
    tau_u: float = param(0.5, float, low=0.0, low_open=True, doc="time constant of the recovery (time units)")
    dt: float = param(0.005, float, low=0.0, low_open=True, doc="Euler step (time units)")
    noise: float = param(0.01, float, low=0.0, doc="sigma, the input noise's standard deviation (a.u. of v per sqrt time unit)")
    gain_base: float = param(0.5, float, low=0.0, doc="G, gain of the decision at zero firing")
    gain_scale: float = param(3.0, float, low=0.0, doc="k, gain per unit of firing rate")

    def __post_init__(self):
        check_params(self)
        if self.dt > self.tau_v / 5:
            raise ConfigError(type(self).__name__, "dt", f"at most tau_v / 5 = {self.tau_v / 5:g} (Euler's step "
                              "well below the fast time constant)", repr(self.dt))


@dataclass(frozen=True)
class FHNLCParams(FHNUnitParams):
    substeps: int = param(200, int, low=1, doc="Euler steps per episode: the decision window is substeps x dt")
    pulse: float = param(0.1, float, low=0.0, doc="duration of the evidence input from the window's start (time units)")
    drive: float = param(0.5, float, low=0.0, doc="w, input per unit of engage evidence (a.u. of v per time unit)")


@njit(cache=True, fastmath=False)
def integrate(v, u, inputs, dt, alpha, tau_v, tau_u, mode, baseline, trace):
    """``len(inputs)`` Euler steps of the FitzHugh-Nagumo LC from (v, u), input ``inputs[k]`` at
    step k; writes (v, u) after step k into ``trace[k]`` and returns the final (v, u)."""
    for k in range(inputs.shape[0]):
        dv = (v * (alpha - v) * (v - 1.0) - u + inputs[k]) / tau_v
        du = (mode * v + (1.0 - mode) * baseline - u) / tau_u
        v += dt * dv
        u += dt * du
        trace[k, 0] = v
        trace[k, 1] = u
    return v, u


def with_noise(inputs: np.ndarray, sigma: float, dt: float, rng) -> np.ndarray:
    """``inputs`` (one per Euler step) plus white noise of intensity ``sigma``: Euler-Maruyama,
    sigma xi / sqrt(dt) per step with xi standard normal, so that v moves by sigma sqrt(dt) xi /
    tau_v, as in the noisy LC units of Usher et al. (1999) and Gilzenrat et al. (2002).
    ``inputs`` itself when ``sigma`` is 0 (no draw)."""
    if sigma <= 0.0:
        return inputs
    return inputs + (sigma / np.sqrt(dt)) * rng.standard_normal(len(inputs))


@register("lc.fhn")
class FHNLC(GainLC):
    """A FitzHugh-Nagumo LC (Gilzenrat et al. 2002) driven by the engage evidence; its release is the gain.

    Per pass (one decision window of ``substeps`` Euler steps of ``dt``, the state carried
    over from the previous window):

    - the engage evidence, x = drive x max(0, tanh(Q_eng - Q_dis)), is the input for the
      first ``pulse`` time units of the window;
    - v and u are integrated with the input noise of intensity ``noise`` (module docstring;
      Euler-Maruyama, compiled with numba; :func:`with_noise`);
    - the firing rate r(t) = clip(v(t), 0, 1); the NE released in the window is its mean,
      and the gain = gain_base + gain_scale x mean r, released through the drugs, then the
      softmax decision of :class:`~neurocur.regions.lc_softmax.GainLC`.

    NE: the released level is the gain (``ne_gain``, output ``ne``). ``ne_tonic`` is the
    firing rate at the window's start, before the evidence (the baseline); ``ne_phasic``
    is the burst, the window's peak rate above that baseline (both in [0, 1]; the
    module-learned input is not an input of the dynamics). ``lc_rate`` is the window's
    mean rate and ``lc_drive`` the input x. With ``build(..., record_frames=True)`` the
    sub-step trace ``fhn_v``, ``fhn_u``, ``fhn_rate`` is recorded, one row per Euler step
    (the rows' ``step`` is the episode's first frame plus the sub-step index: a sub-step
    is a time step of the LC, not a frame).
    """

    Params = FHNLCParams
    #: P(decision | state) is the softmax of the window's mean rate, but that rate is an Euler-integrated
    #: trajectory: no closed form in the parameters. A replay integrates it again for each theta
    #: (:mod:`neurocur.fit.replay`); for its dynamical parameters use simulation-based inference
    #: (:mod:`neurocur.fit.sbi`).
    closed_form = False
    probes = (
        *DECISION_PROBES,
        Probe("ne_tonic", "float", "[0, 1]", "firing rate at the window's start (baseline)"),
        Probe("ne_phasic", "float", "[0, 1]", "peak firing rate of the window above the baseline"),
        GAIN_PROBE,
        Probe("lc_rate", "float", "[0, 1]", "mean firing rate over the decision window (the NE released)"),
        Probe("lc_drive", "float", "a.u. of v per time unit", "engage-evidence input x"),
    )
    frame_probes = (
        Probe("fhn_v", "float", "a.u.", "activation v after each Euler step"),
        Probe("fhn_u", "float", "a.u.", "recovery u after each Euler step"),
        Probe("fhn_rate", "float", "[0, 1]", "firing rate clip(v, 0, 1) after each Euler step"),
    )

    def reset(self, rng) -> None:
        self.rng = rng
        #: the input noise's own stream, a child of the region's: the decision's draws do not move it,
        #: so a replay of observed decisions (neurocur.fit) sees the noise the agent saw
        self.noise_rng = rng.spawn(1)[0]
        self.v = self.u = 0.0
        self.trace = np.zeros((self.params.substeps, 2))
        self._rec = (ENGAGE, 0, 0.0, 0.0, self.params.gain_base, 0.0, 0.0)

    def step(self, context, q, module_learned):
        p = self.params
        q_eng, q_dis = float(q[ENGAGE]), float(q[DISENGAGE])
        x = p.drive * phasic_ne(ENGAGE, False, q_eng, q_dis)  # max(0, tanh(Q_eng - Q_dis))
        tonic = min(1.0, max(0.0, self.v))
        inputs = np.zeros(p.substeps)
        inputs[:int(round(p.pulse / p.dt))] = x
        self.v, self.u = integrate(self.v, self.u, with_noise(inputs, p.noise, p.dt, self.noise_rng), p.dt, p.alpha,
                                   p.tau_v, p.tau_u, p.mode, p.baseline, self.trace)
        rate = np.clip(self.trace[:, 0], 0.0, 1.0)
        mean_rate = float(rate.mean())
        gain, _, action, nxt = self.decide(p.gain_base + p.gain_scale * mean_rate, context, q)
        phasic = max(0.0, float(rate.max()) - tonic)
        self._rec = (action, nxt, tonic, phasic, gain, mean_rate, x)
        return action, nxt, gain

    def record(self):
        return self._rec

    def record_frames(self):
        return np.column_stack([self.trace, np.clip(self.trace[:, 0], 0.0, 1.0)])
