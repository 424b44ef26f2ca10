"""The adaptive-gain LC (Aston-Jones & Cohen 2005): utilities on two timescales, the mode switch measured
on the recorded trace when utility falls and rises again, and its circuit file."""

import numpy as np
import pytest
from bound_region import bound, minimal_world
from scipy.stats import fisher_exact

from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.regions.lc_adaptive_gain import AdaptiveGainLC


def _lc(seed=0, **params):
    return bound(AdaptiveGainLC, "LC", world=minimal_world(4), seed=seed, **params)


def _drive(lc, utilities, q=(1.0, 0.0)):
    """Step the LC once per utility in context 1 with fixed Q; the records as an array (action, ..., long)."""
    q = np.asarray(q, dtype=float)
    rows = []
    for u in utilities:
        lc.step(1, q, False, float(u))
        rows.append(lc.record())
    return np.array(rows, dtype=float)


def test_utilities_are_leaky_averages_of_the_dopamine():
    lc, n = _lc(), 40
    rows = _drive(lc, np.full(n, 2.0))
    k = np.arange(1, n + 1)
    np.testing.assert_allclose(rows[:, 5], 2.0 * (1 - (1 - 1 / 5) ** k), rtol=1e-12)  # tau_short = 5 episodes
    np.testing.assert_allclose(rows[:, 6], 2.0 * (1 - (1 - 1 / 50) ** k), rtol=1e-12)  # tau_long = 50


def test_mode_switches_to_tonic_when_utility_falls_and_back_when_it_rises():
    """300 episodes of utility +3, 300 of -3, 300 of +3 again, with engaging worth 1 DA more than leaving."""
    phases = np.repeat([3.0, -3.0, 3.0], 300)
    rows = _drive(_lc(seed=5), phases)
    action, tonic, gain = rows[:, 0], rows[:, 2], rows[:, 4]
    late = [slice(100 + 300 * i, 300 * (i + 1)) for i in range(3)]  # the last 200 episodes of each phase
    tonic_mean = [tonic[s].mean() for s in late]
    assert tonic_mean[1] > tonic_mean[0] + 0.2 and tonic_mean[1] > tonic_mean[2] + 0.2
    assert gain[late[1]].mean() < 0.5 * gain[late[0]].mean() and gain[late[1]].mean() < 0.5 * gain[late[2]].mean()
    # the switch itself: right after the fall the short-term utility drops below the long-term one
    assert tonic[300:320].max() > 0.95 and tonic[300:320].max() > tonic[late[1]].mean()
    # behaviour: the tonic mode leaves the better context more often (measured on the drawn actions)
    leave = [int(action[s].sum()) for s in late]
    for phasic in (0, 2):
        table = [[leave[1], 200 - leave[1]], [leave[phasic], 200 - leave[phasic]]]
        assert leave[1] > leave[phasic] and fisher_exact(table, alternative="greater").pvalue < 1e-4


def test_engagement_needs_both_timescales():
    """Steady high utility is a phasic mode; a short-term drop below a high long-term utility is enough to
    go tonic, and so is a steady low utility."""
    steady_high = _drive(_lc(), np.full(400, 3.0))[-1]
    dip = _drive(_lc(), np.r_[np.full(400, 3.0), np.full(5, -3.0)])[-1]
    steady_low = _drive(_lc(), np.full(400, -3.0))[-1]
    assert steady_high[2] < 0.55 and dip[2] > 0.95 and steady_low[2] > 0.95  # ne_tonic = 1 - engagement


def test_circuit_file_feeds_vtas_dopamine(circuits_dir):
    circuit = Circuit.from_toml(circuits_dir / "lc_adaptive_gain.toml")
    assert circuit.specs["LC"].type_name == "lc.adaptive_gain"
    assert any((k.src, k.signal, k.dst, k.input) == ("VTA", "da", "LC", "da") for k in circuit.links)
    episodes = circuit.build(SyntheticWorld(), seed=1).run(20_000).episodes()
    short = np.zeros(len(episodes))
    s = 0.0
    for i, da in enumerate(episodes["da"]):
        s += (da - s) / 5.0
        short[i] = s
    np.testing.assert_allclose(episodes["utility_short"], short, rtol=1e-12, atol=1e-15)
    assert episodes["ne_tonic"].between(0, 1).all() and episodes["ne_phasic"].between(0, 1).all()
    assert episodes["ne_gain"].between(0.5, 10.0).all()


@pytest.mark.parametrize("params, key, expected", [
    ({"tau_long": 5.0}, "tau_long", "more than tau_short = 5.0"),
    ({"gain_phasic": 0.1}, "gain_phasic", "at least gain_tonic = 0.5"),
    ({"tau_short": 0.5}, "tau_short", "a number >= 1"),
    ({"slope_long": 0.0}, "slope_long", "a number > 0"),
])
def test_bad_parameters_name_the_key(params, key, expected):
    with pytest.raises(ConfigError) as info:
        AdaptiveGainLC("LC", **params)
    assert info.value.key == key and info.value.expected.startswith(expected)


def test_bad_parameter_in_a_circuit_file_names_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('extends = "lc_adaptive_gain"\n[replace.LC]\ntype = "lc.adaptive_gain"\nparams = { tau_short = "fast" }\n')
    with pytest.raises(ConfigError) as info:
        Circuit.from_toml(path)
    assert (info.value.source, info.value.key) == (str(path), "replace.LC.params.tau_short")


def _logistic(x):
    return 1.0 / (1.0 + np.exp(-x))


def test_each_step_applies_the_documented_equations_to_this_episodes_utilities():
    """Row by row against the docstring's equations, written out here: the engagement E of the utilities
    *after* this episode's dopamine, ne_tonic = 1 - E, the gain interpolated by E, and the phasic burst
    scaled by E (1 at a module storage, else max(0, tanh(Q_eng - Q_dis)) on an engage decision)."""
    params = dict(slope_short=1.5, slope_long=0.7, utility_mid=0.4, gain_tonic=0.5, gain_phasic=8.0)
    lc, rng = _lc(seed=2, **params), np.random.default_rng(11)
    for _ in range(300):
        q = rng.normal(size=2)
        learned = bool(rng.random() < 0.1)
        lc.step(1, q, learned, float(rng.normal(0.5, 2.0)))
        action, _, tonic, phasic, gain, short, long = lc.record()
        e = (1.0 - _logistic(params["slope_short"] * (long - short))) * _logistic(
            params["slope_long"] * (long - params["utility_mid"]))
        burst = 1.0 if learned else (max(0.0, np.tanh(q[0] - q[1])) if action == 0 else 0.0)
        np.testing.assert_allclose([tonic, gain, phasic], [1.0 - e, 0.5 + 7.5 * e, e * burst], rtol=1e-12, atol=1e-15)
