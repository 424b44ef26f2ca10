"""The LC model of Gilzenrat, Holmes, Rajkowski, Aston-Jones & Cohen (2002) as published: a
FitzHugh-Nagumo LC driven by the target decision unit, whose slow variable sets the gain of the
decision layer and of a response unit.

Not in the paper (its LC is :mod:`.lc`'s epsilon-greedy rule). Gilzenrat et al. (2002, Neural
Networks 15:647) reduce the LC-cortex network of Usher, Cohen, Servan-Schreiber, Rajkowski &
Aston-Jones (1999, Science 283:549) to three parts, each integrated with Euler's method, step
``dt`` (time in units of the decision units' time constant, 1):

- an input layer I = (I_1 target, I_2 distractor): the frame's two columns
  (:mod:`neurocur.contexts.vigilance`);
- a decision layer of a target unit X_1 and a distractor unit X_2 with self-excitation,
  mutual inhibition and crosstalk, and a response unit X_3 driven by the target unit:

      dx_i/dt = -x_i + w_ii f_i + sum_k w_ik I_k - w_ij f_j + noise      (i, j in {1, 2}, j != i)
      dx_3/dt = -x_3 + w_33 f_3 + w_31 f_1 + noise,
      f_i = 1 / (1 + exp(-g(t) (x_i - b_i))),

  with w_ii = 1 (``self_excitation``), w_ij = 1 (``inhibition``), the input weights 1
  (``input_weight``) to the unit's own pathway and 0.33 (``crosstalk``) to the other's,
  w_33 = 2, w_31 = 1.84, biases b_1 = b_2 = 0 and b_3 = 2 (``response_bias``), and
  normal noise of standard deviation ``noise`` (0.22) per unit;
- the LC, a FitzHugh-Nagumo unit (their eqs 6-8) driven by the target unit's output:

      tau_v dv/dt = v (a - v)(v - 1) - u + w_vX1 f_1,
      tau_u du/dt = h(v) - u,     h(v) = C v + (1 - C) d,

  a = 0.5, d = 0.5, tau_v = 0.05, tau_u = 5, w_vX1 = 0.3, and the mode C: 0.95 phasic, 0.55
  tonic. u is the NE released: the gain of every unit is g(t) = G + k u(t), G = 0.5, k = 3.

The LC and the decision layer are coupled in both directions at every step (the LC reads the
target unit, the units read the LC's gain), so they are one region. Within a step the decision
units move first with the gain the LC released in the previous step, then the LC with the
target unit's new output; the gain of its new u is released at once, and the response unit
moves with it and with the target unit's new output: the order in which PsyNeuLink's
``GilzenratModel`` (the Cohen lab's implementation) updates them, which neurocur reproduces to
1e-8 (``benchmarks/psyneulink_gilzenrat.py``, ``tests/regions/test_gilzenrat_reference.py``).
The noise is Euler-Maruyama's, ``noise`` x sqrt(dt) per step (a standard deviation per unit of
time), as PsyNeuLink's LeakyCompetingIntegrator adds it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..config import ConfigError, check_params, param
from .base import Probe, Region, Signal, register

__all__ = ["GilzenratParams", "GilzenratLC", "decision_lc_step", "response_step", "simulate", "STATE"]

#: The state vector's entries, in order: the units' net inputs x_1, x_2, x_3, their outputs
#: f_1, f_2, f_3, the LC's v and u, and the gain g released by the LC's last step.
STATE = ("x1", "x2", "x3", "f1", "f2", "f3", "v", "u", "gain")


@dataclass(frozen=True)
class GilzenratParams:
    """Gilzenrat et al. (2002)'s parameters (module docstring); time in units of the decision
    units' time constant.

    Parameters
    ----------
    mode : float
        C, in [0, 1]: 0.95 the phasic mode, 0.55 the tonic mode.
    baseline : float
        d, the LC's uncorrelated baseline activity in h(v) = C v + (1 - C) d.
    alpha : float
        a, in (0, 1), the threshold of the cubic v (a - v)(v - 1).
    tau_v : float
        The time constant of v (> 0).
    tau_u : float
        The time constant of u, the NE released (> 0).
    dt : float
        Euler's step (> 0), at most ``tau_v / 2`` (a ``ConfigError`` otherwise).
    lc_weight : float
        w_vX1, the weight of the target unit's output on the LC.
    gain_base : float
        G (>= 0), the gain at u = 0.
    gain_scale : float
        k (>= 0), the gain per unit of u: g = G + k u.
    input_weight : float
        w_XiIi, an input pathway's weight on its own decision unit.
    crosstalk : float
        w_XiIj, an input pathway's weight on the other decision unit.
    self_excitation : float
        w_XiXi (>= 0), a decision unit's weight on itself.
    inhibition : float
        w_XiXj (>= 0), a decision unit's inhibition of the other.
    decision_bias : float
        b_1 = b_2, the decision units' logistic bias.
    response_weight : float
        w_X3X1, the target unit's weight on the response unit.
    response_self : float
        w_X3X3 (>= 0), the response unit's weight on itself.
    response_bias : float
        b_3, the response unit's logistic bias.
    noise : float
        The standard deviation (>= 0) of each unit's noise per unit of time (``noise`` x sqrt(dt) per step).
    threshold : float
        The response criterion on f_3, in (0, 1) (ours: the response unit rests near 0.47 at G + k u).
    initial_v : float
        v at the run's start.
    initial_u : float
        u at the run's start.
    window : int
        Steps from the stimulus onset in which the LC's peak is measured.
    """

    mode: float = param(0.95, float, low=0.0, high=1.0, doc="C: 0.95 phasic mode, 0.55 tonic mode")
    baseline: float = param(0.5, float, doc="d, the LC's uncorrelated baseline activity in h(v)")
    alpha: float = param(0.5, float, low=0.0, high=1.0, low_open=True, high_open=True,
                         doc="a, threshold of the cubic v (a - v)(v - 1)")
    tau_v: float = param(0.05, float, low=0.0, low_open=True, doc="time constant of v")
    tau_u: float = param(5.0, float, low=0.0, low_open=True, doc="time constant of u (NE release)")
    dt: float = param(0.02, float, low=0.0, low_open=True, doc="Euler step")
    lc_weight: float = param(0.3, float, doc="w_vX1, weight of the target unit's output on the LC")
    gain_base: float = param(0.5, float, low=0.0, doc="G, the gain at u = 0")
    gain_scale: float = param(3.0, float, low=0.0, doc="k, gain per unit of u")
    input_weight: float = param(1.0, float, doc="w_XiIi, input pathway to its own decision unit")
    crosstalk: float = param(0.33, float, doc="w_XiIj, input pathway to the other decision unit")
    self_excitation: float = param(1.0, float, low=0.0, doc="w_XiXi, decision unit to itself")
    inhibition: float = param(1.0, float, low=0.0, doc="w_XiXj, decision unit's inhibition of the other")
    decision_bias: float = param(0.0, float, doc="b_1 = b_2, the decision units' logistic bias")
    response_weight: float = param(1.84, float, doc="w_X3X1, target unit to response unit")
    response_self: float = param(2.0, float, low=0.0, doc="w_X3X3, response unit to itself")
    response_bias: float = param(2.0, float, doc="b_3, the response unit's logistic bias")
    noise: float = param(0.22, float, low=0.0, doc="standard deviation of each unit's noise per unit of time")
    threshold: float = param(0.6, float, low=0.0, high=1.0, low_open=True, high_open=True,
                             doc="response criterion on f_3 (ours: the response unit rests near 0.47 at G + k u)")
    initial_v: float = param(0.0, float, doc="v at the run's start")
    initial_u: float = param(0.0, float, doc="u at the run's start")
    window: int = param(100, int, low=1, doc="steps from the stimulus onset in which the LC's peak is measured")

    def __post_init__(self):
        check_params(self)
        if self.dt > self.tau_v / 2:
            raise ConfigError(type(self).__name__, "dt", f"at most tau_v / 2 = {self.tau_v / 2:g} (Euler's "
                              "step below the fast time constant)", repr(self.dt))


@njit(cache=True, fastmath=False)
def _logistic(x, gain, bias):
    return 1.0 / (1.0 + np.exp(-gain * (x - bias)))


@njit(cache=True, fastmath=False)
def decision_lc_step(s, i1, i2, e1, e2, p):
    """The first part of one Euler step of the coupled model (module docstring), on the state ``s``
    (:data:`STATE`, updated in place): the decision units with the inputs ``i1``, ``i2``, their noise
    increments ``e1``, ``e2`` and the gain the LC released in the previous step, ``s[8]``; then the
    LC with their new target output. Returns the LC's new u. ``p`` = (dt, w_in, w_cross, w_self,
    w_inhib, b_dec, w_31, w_33, b_resp, a, C, d, tau_v, tau_u, w_vX1).

    Parameters
    ----------
    s : array of float64, shape (9,)
        The state (``STATE``), updated in place.
    i1 : float
        The target pathway's input I_1.
    i2 : float
        The distractor pathway's input I_2.
    e1 : float
        The target unit's noise increment.
    e2 : float
        The distractor unit's noise increment.
    p : array of float64, shape (15,)
        The parameter vector (``step_params``).

    Returns
    -------
    float
        The LC's new u.
    """
    dt, w_in, w_cross, w_self, w_inhib, b_dec = p[0], p[1], p[2], p[3], p[4], p[5]
    a, c, d, tau_v, tau_u, w_v = p[9], p[10], p[11], p[12], p[13], p[14]
    gain, f1, f2 = s[8], s[3], s[4]
    x1 = s[0] + dt * (-s[0] + w_in * i1 + w_cross * i2 + w_self * f1 - w_inhib * f2) + e1
    x2 = s[1] + dt * (-s[1] + w_cross * i1 + w_in * i2 + w_self * f2 - w_inhib * f1) + e2
    s[0], s[1] = x1, x2
    s[3], s[4] = _logistic(x1, gain, b_dec), _logistic(x2, gain, b_dec)
    v, u = s[6], s[7]
    dv = (v * (a - v) * (v - 1.0) - u + w_v * s[3]) / tau_v
    du = (c * v + (1.0 - c) * d - u) / tau_u
    s[6], s[7] = v + dt * dv, u + dt * du
    return s[7]


@njit(cache=True, fastmath=False)
def response_step(s, gain, e3, p):
    """The second part of the step: the LC releases ``gain`` (G + k u of its new u, through any drug),
    which the response unit reads at once (noise increment ``e3``) and the decision units in the next step.

    Parameters
    ----------
    s : array of float64, shape (9,)
        The state (``STATE``), updated in place.
    gain : float
        The gain the LC releases.
    e3 : float
        The response unit's noise increment.
    p : array of float64, shape (15,)
        The parameter vector (``step_params``).
    """
    dt, w_31, w_33, b_resp = p[0], p[6], p[7], p[8]
    s[2] = s[2] + dt * (-s[2] + w_33 * s[5] + w_31 * s[3]) + e3
    s[5] = _logistic(s[2], gain, b_resp)
    s[8] = gain


@njit(cache=True, fastmath=False)
def _run(s, inputs, noise, p, g0, k, trace):
    for t in range(inputs.shape[0]):
        u = decision_lc_step(s, inputs[t, 0], inputs[t, 1], noise[t, 0], noise[t, 1], p)
        response_step(s, g0 + k * u, noise[t, 2], p)
        trace[t] = s


def step_params(p: GilzenratParams) -> np.ndarray:
    """The parameter vector of :func:`decision_lc_step` and :func:`response_step`."""
    return np.array([p.dt, p.input_weight, p.crosstalk, p.self_excitation, p.inhibition, p.decision_bias,
                     p.response_weight, p.response_self, p.response_bias, p.alpha, p.mode, p.baseline,
                     p.tau_v, p.tau_u, p.lc_weight])


def initial_state(p: GilzenratParams) -> np.ndarray:
    """The run's first state: every unit at x = 0, its output the logistic of it at the first gain,
    v and u at ``initial_v``, ``initial_u``, the gain G + k u."""
    gain = p.gain_base + p.gain_scale * p.initial_u
    f_dec, f_resp = 1.0 / (1.0 + np.exp(gain * p.decision_bias)), 1.0 / (1.0 + np.exp(gain * p.response_bias))
    return np.array([0.0, 0.0, 0.0, f_dec, f_dec, f_resp, p.initial_v, p.initial_u, gain])


def simulate(p: GilzenratParams, inputs: np.ndarray, noise: np.ndarray, state: np.ndarray | None = None,
             drug=None) -> tuple[np.ndarray, np.ndarray]:
    """Integrate ``len(inputs)`` steps from ``state`` (default :func:`initial_state`) with the input
    rows (I_1, I_2) and the noise increments ``noise`` (T, 3); returns the trace (T, 9), the state
    (:data:`STATE`) after each step, and the final state. ``drug``: a function applied to each
    released gain (the NE) before the units read it; a gain it would make negative is released as 0.

    Parameters
    ----------
    p : GilzenratParams
        The model's parameters.
    inputs : array of float, shape (T, 2)
        The input layer (I_1 target, I_2 distractor) at each step.
    noise : array of float, shape (T, 3)
        The noise increments of the units x_1, x_2, x_3 at each step (already scaled by sqrt(dt)).
    state : array of float, shape (9,), optional
        The state to start from (``STATE``; copied); default ``initial_state(p)``.
    drug : callable, optional
        ``gain -> gain``, applied to each released gain; None: no drug.

    Returns
    -------
    trace : array of float64, shape (T, 9)
        The state after each step.
    state : array of float64, shape (9,)
        The final state.
    """
    s = initial_state(p) if state is None else np.array(state, dtype=float)
    inputs, noise = np.ascontiguousarray(inputs, dtype=float), np.ascontiguousarray(noise, dtype=float)
    trace = np.empty((len(inputs), len(STATE)))
    vec = step_params(p)
    if drug is None:
        _run(s, inputs, noise, vec, p.gain_base, p.gain_scale, trace)
    else:
        for t in range(len(inputs)):
            u = decision_lc_step(s, inputs[t, 0], inputs[t, 1], noise[t, 0], noise[t, 1], vec)
            response_step(s, max(0.0, drug(p.gain_base + p.gain_scale * u)), noise[t, 2], vec)
            trace[t] = s
    return trace, s


@register("lc_trial.gilzenrat2002")
class GilzenratLC(Region):
    """Gilzenrat et al. (2002)'s LC and the decision layer it modulates, over a trial's time steps
    (module docstring).

    Per pass (one trial; the state carries over from the previous trial): one Euler step per
    frame, the frame's columns the input layer, with the noise of each unit drawn from the
    region's stream. The released NE is the gain at every step (a drug acts on each step's
    gain before the units read it; the LC's u is unchanged by it).

    Recorded per trial: ``target`` (the stimulus was a target: its target column the larger),
    ``response`` (the response unit's output f_3 crossed ``threshold`` at or after the stimulus
    onset), ``response_step`` (the first step it did, -1 without one), the LC's activity h(v) =
    C v + (1 - C) d (the LC's population output, as the paper plots it): ``lc_baseline`` its
    mean before the onset, ``lc_peak`` its peak within ``window`` steps of the onset,
    ``lc_burst`` = peak - baseline, ``lc_rate`` the trial's mean, and ``ne_gain`` the mean gain
    while the stimulus is on.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"GilzenratLC"``); the constructor is ``Region``'s.
    params : GilzenratParams, optional
        The model's parameters (``GilzenratParams``, field by field).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = GilzenratParams
    modulator = "ne"
    inputs = (Signal("episode", "Episode", (), "one trial: target and distractor pathway inputs (T, 2)"),)
    outputs = ()
    probes = (
        Probe("target", "bool", "", "the trial's stimulus was a target"),
        Probe("response", "bool", "", "the response unit crossed the criterion after the onset"),
        Probe("response_step", "int", "time step", "first step at or after the onset above the criterion (-1: none)"),
        Probe("lc_baseline", "float", "h(v)", "mean LC activity h(v) before the stimulus onset"),
        Probe("lc_peak", "float", "h(v)", "peak LC activity within the window from the onset"),
        Probe("lc_burst", "float", "h(v)", "peak minus baseline"),
        Probe("lc_rate", "float", "h(v)", "mean LC activity over the trial"),
        Probe("ne_gain", "float", "gain", "mean gain G + k u while the stimulus is on (the released NE)"),
    )
    frame_probes = tuple(Probe(f"gilzenrat_{name}", "float", "a.u.", f"{name} after each step") for name in STATE)

    def bind(self, world) -> None:
        if world.n_pixels != 2:
            raise ValueError(f"{self.name}: needs frames of two columns (target, distractor pathway); "
                             f"the world's have {world.n_pixels}")

    def reset(self, rng) -> None:
        self.rng = rng
        self.state = initial_state(self.params)
        self.trace = np.zeros((0, len(STATE)))
        self._rec = (False, False, -1, float("nan"), float("nan"), float("nan"), float("nan"), float("nan"))

    def step(self, episode):
        p = self.params
        frames = episode.frames
        noise = p.noise * np.sqrt(p.dt) * self.rng.standard_normal((len(frames), 3))
        self.trace, self.state = simulate(p, frames, noise, self.state, self.modulate if self.drugs else None)
        on = np.flatnonzero(frames.max(axis=1) > 0)
        onset = int(on[0]) if len(on) else len(frames)
        h = p.mode * self.trace[:, 6] + (1.0 - p.mode) * p.baseline
        baseline = float(h[:onset].mean()) if onset > 0 else float(h[0])
        peak = float(h[onset:onset + p.window].max()) if onset < len(h) else float("nan")
        crossed = np.flatnonzero(self.trace[onset:, 5] > p.threshold)
        target = bool(len(on) and frames[on, 0].max() > frames[on, 1].max())
        gain = float(self.trace[on, 8].mean()) if len(on) else float("nan")  # released while it is on
        self._rec = (target, len(crossed) > 0, int(onset + crossed[0]) if len(crossed) else -1,
                     baseline, peak, peak - baseline, float(h.mean()), gain)
        return ()

    def record(self):
        return self._rec

    def record_frames(self):
        return self.trace
