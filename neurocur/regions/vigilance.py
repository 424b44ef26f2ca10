"""The decision layer of a target-detection task, its gain set by the LC at every time step.

Not in the paper. After the decision layer of Gilzenrat, Holmes, Rajkowski, Aston-Jones &
Cohen (2002, Neural Networks 15:647) and Usher et al. (1999, Science 283:549): a target
and a distractor unit with leaky activations, each driven by its input pathway through a
logistic whose gain the LC sets (Servan-Schreiber, Printz & Cohen 1990, Science 249:892):

    tau dy_i/dt = -y_i + f(g(t) (I_i(t) + noise) - bias),    f the logistic,

with I_i the frame's column i (:mod:`neurocur.contexts.vigilance`: 0 target, 1 distractor
pathway) and g(t) the LC's gain (:mod:`.lc_fhn_trial`). The animal responds when the target
unit crosses ``threshold``: a response on a target trial is a hit, on a distractor trial a
false alarm. Their layer has lateral inhibition and a response unit as well; here the gain
acts on the same kind of unit, which is what sets performance in their account.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register


@dataclass(frozen=True)
class VigilanceParams:
    tau: float = param(10.0, float, low=1.0, doc="time constant of the units (time steps)")
    bias: float = param(2.0, float, doc="bias subtracted inside the logistic")
    threshold: float = param(0.5, float, low=0.0, high=1.0, low_open=True, high_open=True,
                             doc="activation of the target unit that triggers a response")
    noise: float = param(0.5, float, low=0.0, doc="standard deviation of the input noise per time step")

    def __post_init__(self):
        check_params(self)


@register("decision.vigilance")
class VigilanceDecision(Region):
    """Two gain-modulated units, target and distractor, per trial (module docstring).

    Per pass (one trial; both units start at rest, f(-bias)): Euler steps of one time step
    with independent normal input noise per unit and step. Recorded: ``target`` (the
    stimulus was a target: its target column is the larger), ``response`` (the target unit
    crossed ``threshold``), ``response_step`` (the first step it did, -1 without one) and
    ``stimulus_gain`` (the mean gain while the stimulus was on).
    """

    Params = VigilanceParams
    inputs = (
        Signal("episode", "Episode", (), "one trial: target and distractor pathway inputs (T, 2)"),
        Signal("gain", "float64", ("T",), "the LC's gain at every time step"),
    )
    probes = (
        Probe("target", "bool", "", "the trial's stimulus was a target"),
        Probe("response", "bool", "", "the target unit crossed the threshold"),
        Probe("response_step", "int", "time step", "first step above the threshold (-1: none)"),
        Probe("stimulus_gain", "float", "gain", "mean gain while the stimulus was on"),
    )

    def bind(self, world) -> None:
        if world.n_pixels != 2:
            raise ValueError(f"{self.name}: needs frames of two columns (target, distractor pathway); "
                             f"the world's have {world.n_pixels}")

    def reset(self, rng) -> None:
        self.rng = rng
        self._rec = (False, False, -1, float("nan"))

    def step(self, episode, gain):
        p = self.params
        inputs = episode.frames + p.noise * self.rng.standard_normal(episode.frames.shape)
        y = np.full(2, 1.0 / (1.0 + np.exp(p.bias)))
        crossed = -1
        for t in range(len(inputs)):
            drive = 1.0 / (1.0 + np.exp(p.bias - gain[t] * inputs[t]))
            y += (drive - y) / p.tau
            if crossed < 0 and y[0] > p.threshold:
                crossed = t
        on = episode.frames.max(axis=1) > 0
        target = bool(on.any() and episode.frames[on, 0].max() > episode.frames[on, 1].max())
        self._rec = (target, crossed >= 0, crossed, float(gain[on].mean()) if on.any() else float("nan"))
        return ()

    def record(self):
        return self._rec
