"""The replay steps the decision part as a circuit the scheduler builds (neurocur.fit.tape): delayed edges
inside the part read the previous pass's value, the output's initial value on the first, as in the full run.

The circuit is the bandit's with a region between the values and the choice: ``Blend`` mixes PFC's values of this
trial with its own output of the previous trial (a delayed self-loop, ``START`` on the first trial) and adds a trend,
PFC's values of this trial minus those of the previous one (a delayed edge between two regions of the part; none
on the first trial, whose delayed value is PFC's initial None). Replayed with the upstream parameters fitted (PFC's
learning rate, Blend's mix), the log-likelihood equals a full run of the circuit at those parameters and a
plain-numpy recursion of the same model, to 1e-12; a replay that read a delayed edge's value of this pass, or
started one anywhere but at its initial value, would differ by far more. With the choice's released gain fed back
to Blend through a third delayed edge (a decision output other than the observed one: no vectorised path), the
stepped replay equals them too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
from scipy import special

from neurocur.circuit import Circuit, Link, RegionSpec
from neurocur.config import ConfigError, check_params, param
from neurocur.experiments import load_experiment
from neurocur.fit.replay import Replay
from neurocur.fit.study import simulate
from neurocur.regions.base import Region, Signal

START = (0.8, -0.4)
TREND = 0.5
FEEDBACK = 0.05


@dataclass(frozen=True)
class BlendParams:
    mix: float = param(0.5, float, low=0.0, high=1.0, doc="weight of this trial's values")

    def __post_init__(self):
        check_params(self)


class Blend(Region):
    """``mix * values + (1 - mix) * previous + TREND * (values - stale)``: previous = its own output of the
    previous trial (``START`` on the first), stale = PFC's values of the previous trial (no trend on the first)."""

    Params = BlendParams
    inputs = (Signal("values", "float64", ("n_contexts",)), Signal("previous", "float64", ("n_contexts",)),
              Signal("stale", "float64", ("n_contexts",)))
    outputs = (Signal("values", "float64", ("n_contexts",), initial=START),)

    def step(self, values, previous, stale):
        mix, values = self.params.mix, np.asarray(values)
        trend = 0.0 if stale is None else TREND * (values - stale)
        return (mix * values + (1.0 - mix) * np.asarray(previous) + trend,)


class GainBlend(Blend):
    """:class:`Blend` plus ``FEEDBACK * gain * (1, -1)``, gain = the choice's released gain of the previous trial."""

    inputs = (*Blend.inputs, Signal("gain", "float64", ()))

    def step(self, values, previous, stale, gain):
        (out,) = super().step(values, previous, stale)
        return (out + FEEDBACK * (0.0 if gain is None else gain) * np.array([1.0, -1.0]),)


class Condition:
    def __init__(self, circuit, make_world):
        self.circuit, self.make_world = circuit, make_world


def blended(bandit, cls):
    base = bandit.circuit
    specs = {**base.specs, "Blend": RegionSpec("Blend", cls, cls.Params(mix=0.6))}
    links = [k for k in base.links if not (k.src == "PFC" and k.dst == "LC")]
    links += [Link("PFC", "values", "Blend", "values"), Link("Blend", "values", "LC", "values"),
              Link("Blend", "values", "Blend", "previous", delayed=True),
              Link("PFC", "values", "Blend", "stale", delayed=True)]
    if cls is GainBlend:
        links.append(Link("LC", "ne", "Blend", "gain", delayed=True))
    return Condition(Circuit(specs, links), bandit.make_world)


def numpy_logp(choices, outcomes, *, alpha, mix, beta, feedback=False):
    """Per trial, log P(choice): PFC's delta rule gives q_t, Blend b_t = mix q_t + (1 - mix) b_(t-1) +
    TREND (q_t - q_(t-1)) (+ FEEDBACK beta (1, -1) with ``feedback``; b_(-1) = START, no trend nor feedback at
    t = 0), the softmax of trial t on b_t."""
    q, blend, out = np.zeros(2), np.array(START), []
    for t, c in enumerate(choices):
        stale = q.copy()
        if t:
            q[choices[t - 1]] += alpha * (outcomes[t - 1] - q[choices[t - 1]])
        blend = mix * q + (1 - mix) * blend
        if t:
            blend = blend + TREND * (q - stale) + (FEEDBACK * beta * np.array([1.0, -1.0]) if feedback else 0.0)
        out.append(special.log_softmax(beta * blend)[c])
    return np.array(out)


@pytest.fixture(scope="module")
def bandit():
    return load_experiment("bandit").conditions["delta"]


@pytest.mark.parametrize("cls", [Blend, GainBlend])
def test_a_delayed_edge_inside_the_decision_part_is_replayed_as_the_scheduler_runs_it(bandit, cls):
    condition = blended(bandit, cls)
    trials, _ = simulate(condition, {}, np.random.SeedSequence(3), 120, name="agent")
    fitted = ["PFC.alpha", "Blend.mix", "LC.beta"]
    replay = Replay(condition.circuit, condition.make_world(), 4, trials, fitted=fitted)
    assert replay.part == ("PFC", "Blend", "LC")
    assert replay._separable is (cls is Blend)  # the fed-back gain leaves the vectorised path
    for alpha, mix, beta in ((0.3, 0.6, 3.0), (0.8, 0.2, 7.0), (0.05, 0.95, 1.5)):
        theta = {"PFC.alpha": alpha, "Blend.mix": mix, "LC.beta": beta}
        full = Replay(condition.circuit.with_params(theta), condition.make_world(), 4, trials, fitted=fitted).logp
        expected = numpy_logp(trials.choices, trials.outcomes, alpha=alpha, mix=mix, beta=beta,
                              feedback=cls is GainBlend)
        np.testing.assert_allclose(full, expected, rtol=0, atol=1e-12)  # the full run is the model
        np.testing.assert_allclose(replay.episode_logp(theta), full, rtol=0, atol=1e-12)
        assert abs(replay.loglik(theta) - full.sum()) < 1e-12
    first = numpy_logp(trials.choices, trials.outcomes, alpha=0.3, mix=0.6, beta=3.0)[0]
    assert abs(first - math.log(0.5)) > 0.1  # the first choice reads START, not equal values


def test_a_theta_for_a_region_the_replay_does_not_step_again_is_refused(bandit):
    trials, _ = simulate(bandit, {}, np.random.SeedSequence(1), 40, name="agent")
    replay = Replay(bandit.circuit, bandit.make_world(), 1, trials, fitted=["LC.beta"])
    assert replay.part == ("LC",)
    with pytest.raises(ConfigError, match="PFC.alpha.*decision part"):
        replay.episode_logp({"PFC.alpha": 0.9})
