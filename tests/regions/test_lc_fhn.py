"""The FitzHugh-Nagumo LC (Gilzenrat et al. 2002): the Euler trace against an ODE solver, phasic bursts
to engage evidence in the phasic mode, a higher baseline and weak bursts in the tonic mode (measured on
the sub-step trace), the gain read from the released NE, and the recorded fine-grained trace."""

import numpy as np
import pytest
from bound_region import bound, minimal_world
from scipy.integrate import solve_ivp

from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.regions.lc_fhn import FHNLC

EVIDENCE, NONE = np.array([1.0, 0.0]), np.array([0.0, 1.0])  # Q = (engage, disengage)


def _lc(seed=0, **params):
    return bound(FHNLC, "LC", world=minimal_world(4), seed=seed, **params)


def _windows(lc, qs):
    """Step the LC once per Q; the sub-step traces (windows, substeps, 3) and the records."""
    traces, records = [], []
    for q in qs:
        lc.step(1, q, False)
        traces.append(lc.record_frames())
        records.append(lc.record())
    return np.array(traces), np.array(records, dtype=float)


def _euler_error(dt):
    """Max |Euler - reference| over three windows (evidence, none, evidence) of 1 time unit, the
    reference being scipy's adaptive RK45 on the same equations at a tight tolerance."""
    lc = _lc(dt=dt, substeps=round(1.0 / dt), noise=0.0)
    p = lc.params
    traces, _ = _windows(lc, [EVIDENCE, NONE, EVIDENCE])
    x = p.drive * np.tanh(1.0)

    def rhs(t, y):
        v, u = y
        inp = x if (t % 1.0) < p.pulse and (t // 1.0) != 1 else 0.0
        return [(v * (p.alpha - v) * (v - 1) - u + inp) / p.tau_v, (p.mode * v + (1 - p.mode) * p.baseline - u) / p.tau_u]

    t = dt * np.arange(1, 3 * p.substeps + 1)
    ref = solve_ivp(rhs, (0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-9, atol=1e-11, max_step=0.001).y.T
    assert ref[:, 0].max() > 0.5  # the reference bursts: the comparison covers a spike
    return np.abs(traces[:, :, :2].reshape(-1, 2) - ref).max()


def test_euler_trace_follows_the_ode_to_first_order():
    coarse, fine = _euler_error(0.005), _euler_error(0.0025)
    assert coarse < 0.05 and 1.6 < coarse / fine < 2.4  # Euler: the error halves with the step


def _mode_summary(mode):
    """Alternate no-evidence and evidence windows; after 10 windows of settling, the baseline rate
    (mean rate of the no-evidence windows), the burst (peak rate of an evidence window above its
    first sub-step) and the gain in each kind of window, all from the sub-step trace."""
    lc = _lc(mode=mode, noise=0.0)
    traces, records = _windows(lc, [EVIDENCE if i % 2 else NONE for i in range(50)])
    rate = traces[10:, :, 2]
    ev, no = rate[1::2], rate[0::2]
    return {"baseline": no.mean(), "burst": (ev.max(axis=1) - ev[:, 0]).mean(),
            "gain_ev": records[11::2, 4].mean(), "gain_no": records[10::2, 4].mean()}


def test_phasic_mode_bursts_to_engage_evidence():
    s = _mode_summary(1.0)
    assert s["baseline"] < 0.01 and s["burst"] > 0.5
    assert s["gain_ev"] > s["gain_no"] + 0.2  # the burst raises the gain of the decision it drives


def test_tonic_mode_fires_more_at_baseline_and_bursts_weakly():
    phasic, tonic = _mode_summary(1.0), _mode_summary(0.4)
    assert tonic["baseline"] > phasic["baseline"] + 0.5
    assert tonic["burst"] < 0.5 * phasic["burst"]
    assert abs(tonic["gain_ev"] - tonic["gain_no"]) < 0.5 * (phasic["gain_ev"] - phasic["gain_no"])


def test_lowering_the_mode_raises_the_baseline_step_by_step():
    baselines = [_mode_summary(m)["baseline"] for m in (1.0, 0.8, 0.6, 0.4)]
    assert np.all(np.diff(baselines) > 0.02)


def test_probes_are_read_off_the_trace_and_the_gain_off_the_mean_rate():
    lc = _lc(mode=0.6)
    traces, records = _windows(lc, [EVIDENCE, NONE] * 10)
    rate = traces[:, :, 2]
    p = lc.params
    np.testing.assert_allclose(records[:, 5], rate.mean(axis=1), rtol=1e-12)  # lc_rate
    np.testing.assert_allclose(records[:, 4], p.gain_base + p.gain_scale * rate.mean(axis=1), rtol=1e-12)  # ne_gain
    start = np.r_[0.0, rate[:-1, -1]]  # the rate at a window's start is the last one of the previous window
    np.testing.assert_allclose(records[:, 2], start, atol=1e-15)  # ne_tonic
    np.testing.assert_allclose(records[:, 3], np.maximum(0.0, rate.max(axis=1) - start), atol=1e-15)  # ne_phasic
    np.testing.assert_allclose(records[:, 6], np.tile([p.drive * np.tanh(1.0), 0.0], 10), rtol=1e-12)  # lc_drive


def test_disengage_rate_is_the_logistic_of_the_released_gain():
    lc, n = _lc(seed=2, mode=0.4, gain_scale=1.0), 4000  # tonic: a steady gain near 0.5 + 0.87
    q = np.array([0.0, 1.0])
    actions, gains = zip(*[(lc.step(1, q, False)[0], lc.record()[4]) for _ in range(n)])
    p = 1.0 / (1.0 + np.exp(-np.array(gains)))
    assert abs(np.mean(actions) - p.mean()) < 4 * np.sqrt(p.mean() * (1 - p.mean()) / n)


def test_circuit_file_records_the_sub_step_trace_on_request(circuits_dir):
    circuit = Circuit.from_toml(circuits_dir / "lc_fhn.toml")
    assert circuit.specs["LC"].type_name == "lc.fhn"
    sim = circuit.build(SyntheticWorld(), seed=1, record_frames=True).run(3000)
    episodes, probes = sim.episodes(), sim.probes()
    v = probes[(probes["region"] == "LC") & (probes["signal"] == "fhn_v")]
    assert len(v) == 200 * len(episodes)
    rate = probes[(probes["region"] == "LC") & (probes["signal"] == "fhn_rate")]
    means = rate.groupby("episode")["value"].mean().to_numpy()
    np.testing.assert_allclose(episodes["lc_rate"], means, rtol=1e-12)
    assert episodes["ne_tonic"].between(0, 1).all() and episodes["ne_phasic"].between(0, 1).all()
    assert "fhn_v" not in circuit.build(SyntheticWorld(), seed=1).run(300).probes()["signal"].unique()


def test_bad_parameters_name_the_key():
    with pytest.raises(ConfigError, match=r"FHNLCParams: key 'dt': expected at most tau_v / 5 = 0.01"):
        FHNLC("LC", dt=0.02)
    with pytest.raises(ConfigError, match=r"key 'mode': expected a number >= 0 and <= 1, got 1.5"):
        FHNLC("LC", mode=1.5)


def test_default_noise_moves_the_phasic_baseline_without_spontaneous_bursts():
    """The default input noise (sigma = 0.01, docs/regions.md) makes the tonic trace fluctuate
    (sd above 0.01) while the phasic mode stays below the burst threshold without evidence; the
    draws are the region's generator's, so a seed repeats them."""
    def baseline(seed):
        lc = _lc(seed=seed)
        _, records = _windows(lc, [NONE] * 300)
        return records[20:, 2]

    tonic = baseline(3)
    assert tonic.std() > 0.01 and tonic.max() < 0.5
    np.testing.assert_array_equal(tonic, baseline(3))
    assert not np.array_equal(tonic, baseline(4))
    _, quiet = _windows(_lc(noise=0.0), [NONE] * 20)
    assert np.all(quiet[:, 2] == 0.0)  # without noise the phasic mode rests at v = 0
