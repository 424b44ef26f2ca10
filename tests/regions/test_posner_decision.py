"""Target detection in the Posner task (Yu & Dayan 2005; docs/regions.md, ``decision.posner``): the cue's
prior and sensory samples to a posterior bound, against Wald's sequential-test formulas for the accuracy
and the mean sample count of valid and invalid trials."""

import math

import numpy as np
import pytest
from posner_trials import H, trial

from neurocur.contexts.posner import PosnerWorld
from neurocur.regions.posner import PosnerDecision


def _wald(start, bound, noise):
    """A random walk of log-odds l from ``start`` in the target's favour, steps N(2 / noise^2, 4 / noise^2),
    absorbed at +/- ``bound``: P(correct) from the martingale exp(-l), E[n] from Wald's identity, with
    each bound moved out by Siegmund's mean overshoot 0.5826 sd of a step (Siegmund 1985, ch. X)."""
    bound += 0.5826 * 2 / noise
    up = (math.exp(bound) - math.exp(-start)) / (math.exp(bound) - math.exp(-bound))
    return up, (up * bound - (1 - up) * bound - start) / (2 / noise ** 2)


def _run(ach, attended_agrees, n, noise=20.0, bound=0.95):
    region = PosnerDecision("decision", noise=noise, bound=bound, max_samples=20000)
    region.bind(PosnerWorld(cues=H))
    region.reset(np.random.default_rng(3))
    cues = np.array([1.0, 0.0, 1.0])
    episode = trial(cues, 1.0 if attended_agrees else 0.0, relevant=0)
    out = []
    for _ in range(n):
        region.step(episode, ach, 0)
        out.append(region.record())
    valid, cued, rt, correct, prior = map(np.array, zip(*out))
    return rt, correct, valid, cued, prior


def test_valid_and_invalid_trials_against_walds_formulas():
    """ACh 0.1 (gamma* = 0.9, l_0 = +/-2.2), bound 0.95 (2.94), sigma 20: P(correct) 0.997 valid and
    0.554 invalid, mean samples 157 and 505, a validity effect of 347. Without the prior (l_0 = 0)
    both would be 0.95 and about 450 samples: no validity effect."""
    bound, start = math.log(0.95 / 0.05), math.log(0.9 / 0.1)
    rt_v, correct_v, valid_v, cued_v, prior_v = _run(0.1, True, 3000)
    rt_i, correct_i, valid_i, cued_i, prior_i = _run(0.1, False, 3000)
    up_v, n_v = _wald(start, bound, 20.0)
    up_i, n_i = _wald(-start, bound, 20.0)
    assert valid_v.all() and cued_v.all() and not valid_i.any() and not cued_i.any()
    np.testing.assert_allclose(prior_v, 0.9)
    np.testing.assert_allclose(prior_i, 0.1)
    assert abs(correct_v.mean() - up_v) < 0.005 and abs(correct_i.mean() - up_i) < 4 * math.sqrt(0.25 / 3000)
    assert rt_v.mean() == pytest.approx(n_v, rel=0.08) and rt_i.mean() == pytest.approx(n_i, rel=0.05)
    assert rt_i.mean() - rt_v.mean() == pytest.approx(n_i - n_v, rel=0.06)


def test_the_validity_effect_grows_with_the_believed_validity():
    effects = []
    for ach in (0.45, 0.3, 0.15, 0.05):
        rt_v = _run(ach, True, 600, noise=2.0, bound=0.99)[0]
        rt_i = _run(ach, False, 600, noise=2.0, bound=0.99)[0]
        effects.append(rt_i.mean() - rt_v.mean())
    assert all(b > a + 0.5 for a, b in zip(effects, effects[1:])), effects
    assert _run(0.7, True, 1, noise=2.0)[4][0] == 0.5  # an ACh above 0.5 leaves the cue uninformative
