"""LC variant for trial tasks: the FitzHugh-Nagumo LC driven by the stimulus, one Euler step per frame.

Not in the paper. The same unit as :mod:`.lc_fhn` (Gilzenrat, Holmes, Rajkowski,
Aston-Jones & Cohen 2002, Neural Networks 15:647; :func:`~.lc_fhn.integrate`), for a task
whose episode is one trial of time steps (:mod:`neurocur.contexts.vigilance`): the input
at step t is ``drive`` times the frame's column ``channel`` (the task-relevant pathway,
which in their model drives the LC through the target-detection unit) plus the input noise,
and the LC's output is the gain of the decision layer at every step, g(t) = G + k r(t)
with r = clip(v, 0, 1) (their gain equation), which :mod:`.vigilance` reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import param
from .base import Probe, Region, Signal, register
from .lc_fhn import FHNUnitParams, integrate, with_noise


@dataclass(frozen=True)
class FHNTrialParams(FHNUnitParams):
    """:class:`~neurocur.regions.lc_fhn.FHNUnitParams` (one Euler step ``dt`` per frame) and the task's
    input and read-out."""

    drive: float = param(0.3, float, low=0.0, doc="w, input per unit of the stimulus column (a.u. of v per time unit)")
    channel: int = param(0, int, low=0, doc="the frame's column that drives the LC")
    window: int = param(60, int, low=1, doc="time steps from the stimulus onset in which the burst is measured")


@register("lc_trial.fhn")
class FHNTrialLC(Region):
    """The FitzHugh-Nagumo LC over a trial's time steps; emits the decision layer's gain per step.

    Per pass (one trial, state carried over from the previous trial): the input of step t
    is ``drive x frames[t, channel]`` plus white noise of intensity ``noise``; the unit is
    integrated one Euler step per frame; the released NE is the gain g(t) = G + k r(t)
    (output ``gain``, one value per frame; a drug acts on every step's level).

    Recorded per trial: ``lc_baseline`` the mean rate before the stimulus onset (the first
    frame where the channel is on; the whole trial when it never is), ``lc_peak`` the peak
    rate within ``window`` steps from the onset, ``lc_burst`` = peak - baseline, and
    ``lc_rate`` the trial's mean rate (the NE released).
    """

    Params = FHNTrialParams
    modulator = "ne"
    inputs = (Signal("episode", "Episode", (), "one trial; column channel is the LC's input (T, n)"),)
    outputs = (Signal("gain", "float64", ("T",), "gain of the decision layer at every time step (the released NE)"),)
    probes = (
        Probe("lc_baseline", "float", "[0, 1]", "mean firing rate before the stimulus onset"),
        Probe("lc_peak", "float", "[0, 1]", "peak firing rate within the window from the onset"),
        Probe("lc_burst", "float", "[0, 1]", "peak minus baseline"),
        Probe("lc_rate", "float", "[0, 1]", "mean firing rate over the trial (the NE released)"),
    )

    def bind(self, world) -> None:
        if self.params.channel >= world.n_pixels:
            raise ValueError(f"{self.name}: channel must be < {world.n_pixels} (the world's frame columns); "
                             f"got {self.params.channel}")

    def reset(self, rng) -> None:
        self.rng = rng
        self.v = self.u = 0.0
        self._rec = (0.0, 0.0, 0.0, 0.0)

    def step(self, episode):
        p = self.params
        stimulus = episode.frames[:, p.channel]
        inputs = with_noise(p.drive * stimulus, p.noise, p.dt, self.rng)
        trace = np.empty((len(inputs), 2))
        self.v, self.u = integrate(self.v, self.u, inputs, p.dt, p.alpha, p.tau_v, p.tau_u, p.mode, p.baseline, trace)
        rate = np.clip(trace[:, 0], 0.0, 1.0)
        on = np.flatnonzero(stimulus > 0)
        onset = int(on[0]) if len(on) else len(rate)
        baseline = float(rate[:onset].mean()) if onset > 0 else float(rate[0])
        peak = float(rate[onset:onset + p.window].max()) if onset < len(rate) else float("nan")
        self._rec = (baseline, peak, peak - baseline, float(rate.mean()))
        gain = p.gain_base + p.gain_scale * rate
        if self.drugs:
            gain = np.array([self.modulate(g) for g in gain])
        return (gain,)

    def record(self):
        return self._rec
