"""Gilzenrat et al. (2002)'s model (``lc_trial.gilzenrat2002``) against PsyNeuLink's ``GilzenratModel``,
the Cohen lab's implementation: the trajectories and statistics pinned in tests/data/gilzenrat_psyneulink.json
by benchmarks/psyneulink_gilzenrat.py (docs/validation.md); and the adaptive-gain rule against PsyNeuLink's
DualAdaptiveIntegrator, a different rule."""

import json
from pathlib import Path

import numpy as np
import pytest
from bound_region import bound, minimal_world
from scipy.stats import norm

from neurocur.regions.lc_adaptive_gain import AdaptiveGainLC
from neurocur.regions.lc_gilzenrat import STATE, GilzenratParams, simulate

REFERENCE = json.loads((Path(__file__).parents[1] / "data" / "gilzenrat_psyneulink.json").read_text())
COLUMNS = [STATE.index(c) for c in ("f1", "f2", "f3", "v", "u", "gain")]


def _params(mode: str, **extra) -> GilzenratParams:
    c, h0, u0 = REFERENCE["modes"][mode]
    d = REFERENCE["params"]["baseline"]
    return GilzenratParams(mode=c, initial_v=(h0 - (1 - c) * d) / c, initial_u=u0, **extra)


def _start(p: GilzenratParams, mode: str) -> np.ndarray:
    """PsyNeuLink's first state: x = 0, the outputs it gives the units before their first step."""
    f1, f2, f3 = REFERENCE["initial_outputs"][mode]
    return np.array([0.0, 0.0, 0.0, f1, f2, f3, p.initial_v, p.initial_u, p.gain_base + p.gain_scale * p.initial_u])


def _run(mode: str, **extra) -> np.ndarray:
    p = _params(mode, **extra)
    inputs = np.array(REFERENCE["inputs"])
    trace, _ = simulate(p, inputs, np.zeros((len(inputs), 3)), _start(p, mode))
    return trace[:, COLUMNS]


@pytest.mark.parametrize("mode", ["phasic", "tonic"])
def test_trajectories_equal_psyneulinks(mode):
    """400 steps without noise (nothing, a target, nothing, a distractor): the decision and response units'
    outputs, v, u and the released gain equal PsyNeuLink's to 1e-8."""
    np.testing.assert_allclose(_run(mode), np.array(REFERENCE["trajectories"][mode]), rtol=0, atol=1e-8)


def test_the_reference_tells_a_plausible_wrong_model_apart():
    """The comparison can fail: the gain read from v instead of u (a model the pinned file must reject),
    or the LC's d of the other sign, move the trajectories by far more than the tolerance."""
    ref = np.array(REFERENCE["trajectories"]["phasic"])
    assert np.abs(_run("phasic", baseline=-0.5) - ref).max() > 1e-2
    wrong_gain = _run("phasic")
    assert np.abs(wrong_gain[:, 5] - (0.5 + 3.0 * wrong_gain[:, 3])).max() > 0.1  # g(t) = G + k v would differ
    assert REFERENCE["source"].startswith("psyneulink")


def _task(mode: str):
    """The pinned task: the same stimuli and the same noise draws as the benchmark's transcription."""
    t, c = REFERENCE["task"], REFERENCE["modes"][mode][0]
    rng = np.random.default_rng(t["seed"])
    targets = rng.random(t["trials"]) < t["target_probability"]
    inputs = np.zeros((t["trials"], t["trial_length"], 2))
    on = slice(t["onset"], t["onset"] + t["duration"])
    inputs[targets, on] = (1.0, 0.0)
    inputs[~targets, on] = (0.0, 1.0)
    p = _params(mode, noise=REFERENCE["params"]["noise"])
    noise = p.noise * np.sqrt(p.dt) * np.random.default_rng(t["seed"]).standard_normal((t["trials"] * t["trial_length"], 3))
    trace, _ = simulate(p, inputs.reshape(-1, 2), noise, _start(p, mode))
    trials = trace.reshape(t["trials"], t["trial_length"], -1)[t["dropped"]:]
    h = c * trials[:, :, STATE.index("v")] + (1 - c) * p.baseline
    return t, targets[t["dropped"]:], h, trials


@pytest.mark.parametrize("mode", ["phasic", "tonic"])
def test_task_statistics_equal_the_references(mode):
    t, targets, h, trials = _task(mode)
    baseline = h[:, :t["onset"]].mean(axis=1)
    peak = h[:, t["onset"]:t["onset"] + t["window"]].max(axis=1)
    response = (trials[:, t["onset"]:, STATE.index("f3")] > t["threshold"]).any(axis=1)
    hits, fas = response[targets].sum(), response[~targets].sum()
    d = norm.ppf((hits + 0.5) / (targets.sum() + 1)) - norm.ppf((fas + 0.5) / ((~targets).sum() + 1))
    ref = REFERENCE["statistics"][mode]
    assert baseline.mean() == pytest.approx(ref["baseline"], abs=1e-8)
    assert peak[targets].mean() / baseline.mean() == pytest.approx(ref["burst_ratio"], abs=1e-8)
    assert response[targets].mean() == pytest.approx(ref["hit_rate"], abs=1e-12)
    assert response[~targets].mean() == pytest.approx(ref["false_alarm_rate"], abs=1e-12)
    assert d == pytest.approx(ref["d_prime"], abs=1e-8)


def test_psyneulinks_own_noisy_runs_agree_with_the_reference_statistics():
    """PsyNeuLink's own noisy runs (fewer trials, its own draws) against the transcription's: the LC's
    baseline within 0.02 and the phasic mode's burst ratio above the tonic's in both."""
    own = REFERENCE.get("statistics_psyneulink")
    if own is None:
        pytest.skip("the reference was written without PsyNeuLink's noisy runs")
    for mode in ("phasic", "tonic"):
        assert own[mode]["baseline"] == pytest.approx(REFERENCE["statistics"][mode]["baseline"], abs=0.02)
    assert own["phasic"]["burst_ratio"] > own["tonic"]["burst_ratio"]


def test_adaptive_gain_is_a_different_rule_from_psyneulinks_dual_adaptive_integrator():
    """lc.adaptive_gain is named a different rule (docs/validation.md): PsyNeuLink's DualAdaptiveIntegrator
    as it runs gives (1 - logistic(g_s s - b_s)) x logistic(g_l l - b_l) with averages that its code updates
    as (1 - previous) x rate + previous x input (the EWMA's arguments swapped); the pinned trace equals that
    form to 1e-10, and lc.adaptive_gain's E on the same utilities (tau = 1 / rate) does not come near it."""
    ag = REFERENCE["adaptive_gain"]
    a, utilities, pinned = ag["params"], np.array(ag["utilities"]), np.array(ag["engagement"])
    s = l_avg = 0.0
    form = []
    for u in utilities:
        s, l_avg = (1 - s) * a["short_term_rate"] + s * u, (1 - l_avg) * a["long_term_rate"] + l_avg * u
        form.append((1 - 1 / (1 + np.exp(-a["short_term_gain"] * s + a["short_term_bias"])))
                    / (1 + np.exp(-a["long_term_gain"] * l_avg + a["long_term_bias"])))
    np.testing.assert_allclose(form, pinned, rtol=0, atol=1e-10)
    lc = bound(AdaptiveGainLC, "LC", world=minimal_world(4), seed=0, tau_short=1 / a["short_term_rate"],
               tau_long=1 / a["long_term_rate"], slope_short=a["short_term_gain"], slope_long=a["long_term_gain"],
               utility_mid=a["long_term_bias"] / a["long_term_gain"])
    ours = []
    for u in utilities:
        lc.step(1, np.array([1.0, 0.0]), False, float(u))
        ours.append(1.0 - lc.record()[2])  # ne_tonic = 1 - E
    assert np.abs(np.array(ours) - pinned).max() > 0.2
