"""lc_trial.gilzenrat2002 (Gilzenrat et al. 2002) as a region: a trial's records from its own trace, the state
carried over, a drug on the released gain, the LC's rest point, and bad parameters. Its trajectories against
PsyNeuLink's: test_gilzenrat_reference.py."""

from types import SimpleNamespace

import numpy as np
import pytest
from bound_region import bound
from scipy.optimize import brentq

from neurocur.config import ConfigError
from neurocur.contexts.base import Episode
from neurocur.contexts.vigilance import VigilanceWorld
from neurocur.regions.lc_gilzenrat import STATE, GilzenratLC, GilzenratParams, initial_state, simulate
from neurocur.regions.pharmacology import Clamp, Scale


def _episode(target: bool, length=300, onset=100, duration=100) -> Episode:
    frames = np.zeros((length, 2))
    frames[onset:onset + duration] = (1.0, 0.0) if target else (0.0, 1.0)
    return Episode(frames=frames, states=np.arange(length), context=0)


def _region(seed=3, **params):
    return bound(GilzenratLC, "LC", world=VigilanceWorld(), seed=seed, **params)


def test_a_trials_records_come_from_its_trace_with_the_regions_noise():
    lc, ep = _region(), _episode(True)
    lc.step(ep)
    target, response, response_step, baseline, peak, burst, rate, gain = lc.record()
    p = lc.params
    noise = p.noise * np.sqrt(p.dt) * np.random.default_rng(3).standard_normal((300, 3))
    trace, _ = simulate(p, ep.frames, noise)
    np.testing.assert_allclose(lc.trace, trace, rtol=0, atol=1e-14)
    h = p.mode * trace[:, STATE.index("v")] + (1 - p.mode) * p.baseline
    above = np.flatnonzero(trace[100:, STATE.index("f3")] > p.threshold)
    assert target and response == (len(above) > 0)
    assert response_step == (100 + above[0] if len(above) else -1)
    assert baseline == pytest.approx(h[:100].mean(), abs=1e-14)
    assert peak == pytest.approx(h[100:200].max(), abs=1e-14) and burst == pytest.approx(peak - baseline, abs=1e-14)
    assert rate == pytest.approx(h.mean(), abs=1e-14)
    assert gain == pytest.approx(trace[100:200, STATE.index("gain")].mean(), abs=1e-14)


def test_the_state_carries_over_from_trial_to_trial():
    lc = _region(noise=0.0)
    first, second = _episode(True), _episode(False)
    lc.step(first)
    lc.step(second)
    both, _ = simulate(lc.params, np.vstack([first.frames, second.frames]), np.zeros((600, 3)))
    np.testing.assert_allclose(lc.trace, both[300:], rtol=0, atol=1e-14)


def test_a_clamped_gain_is_what_every_unit_reads():
    """With the released gain clamped at 2, the response unit's output is the logistic of its net input at
    gain 2 at every step, and the decision units' likewise (worked from the recorded x)."""
    lc = _region(noise=0.0)
    lc.drugs = (Clamp(level=2.0),)
    lc.step(_episode(True))
    t = lc.trace
    assert np.all(t[:, STATE.index("gain")] == 2.0)
    np.testing.assert_allclose(t[:, STATE.index("f3")], 1 / (1 + np.exp(-2.0 * (t[:, STATE.index("x3")] - 2.0))),
                               rtol=0, atol=1e-14)
    np.testing.assert_allclose(t[1:, STATE.index("f1")], 1 / (1 + np.exp(-2.0 * t[1:, STATE.index("x1")])),
                               rtol=0, atol=1e-14)


def test_a_drug_never_releases_a_negative_gain():
    lc = _region(noise=0.0)
    lc.drugs = (Clamp(level=-1.0), Scale(factor=2.0))
    lc.step(_episode(True))
    assert np.all(lc.trace[:, STATE.index("gain")] == 0.0)
    np.testing.assert_allclose(lc.trace[:, STATE.index("f3")], 0.5, rtol=0, atol=1e-15)  # logistic at gain 0


@pytest.mark.parametrize("mode", [0.95, 0.55])
def test_without_a_stimulus_the_lc_settles_at_its_rest_point(mode):
    """Decision units at x = 0 (outputs 1/2, the LC's input 0.3 x 1/2): the LC settles where the nullclines
    meet, v (a - v)(v - 1) - h(v) + 0.15 = 0 with u = h(v) = C v + (1 - C) d, solved by brentq."""
    p = GilzenratParams(mode=mode, noise=0.0)
    trace, _ = simulate(p, np.zeros((20000, 2)), np.zeros((20000, 3)))
    h = lambda v: mode * v + (1 - mode) * p.baseline  # noqa: E731
    v_rest = brentq(lambda v: v * (p.alpha - v) * (v - 1) - h(v) + 0.3 * 0.5, -0.5, 0.4)
    assert trace[-1, STATE.index("v")] == pytest.approx(v_rest, abs=1e-6)
    assert trace[-1, STATE.index("u")] == pytest.approx(h(v_rest), abs=1e-6)
    assert trace[-1, STATE.index("gain")] == pytest.approx(p.gain_base + p.gain_scale * h(v_rest), abs=1e-5)


def test_the_first_state_and_bad_parameters():
    p = GilzenratParams(initial_u=0.2)
    np.testing.assert_allclose(initial_state(p), [0, 0, 0, 0.5, 0.5, 1 / (1 + np.exp(1.1 * 2)), 0, 0.2, 1.1])
    with pytest.raises(ConfigError, match="dt"):
        GilzenratParams(dt=0.03)
    with pytest.raises(ValueError, match="two columns"):
        GilzenratLC("LC").bind(SimpleNamespace(n_pixels=3))
