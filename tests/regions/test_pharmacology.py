"""Drug lesions (clamp, scale, noise) on a region's released neuromodulator, from Python and TOML."""

from __future__ import annotations

import tempfile
import textwrap
from pathlib import Path

import numpy as np
import pytest
from bound_region import minimal_world

from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.regions import REGIONS
from neurocur.regions.base import Probe, Region, Signal
from neurocur.regions.pharmacology import Clamp, Noise, Scale


@REGIONS.register("toy.transmitter")
class Transmitter(Region):
    """Releases level = 1 + pass index (a neuromodulator, ``"toy"``) and draws one random
    number per pass from its own stream (to show the drug's stream is separate)."""

    modulator = "toy"
    outputs = (Signal("level", "float64", ()),)
    probes = (Probe("level", "float", "a.u."), Probe("own_draw", "float", "a.u."))

    def reset(self, rng):
        self.rng, self.k = rng, 0

    def step(self):
        self.k += 1
        self.draw = self.rng.random()
        self.level = self.modulate(float(self.k))
        return (self.level,)

    def record(self):
        return (self.level, self.draw)


@REGIONS.register("toy.sink")
class Sink(Region):
    inputs = (Signal("level", "float64", ()),)
    lesions = {"off": {}}


_TOY = textwrap.dedent("""
    [regions.T]
    type = "toy.transmitter"
    [regions.S]
    type = "toy.sink"
    [[edges]]
    from = "T"
    signal = "level"
    to = "S"
""")


_DIR = Path(tempfile.mkdtemp(prefix="pharmacology-"))


def _write_toy(extra: str = "") -> str:
    path = _DIR / f"toy{len(list(_DIR.iterdir()))}.toml"
    path.write_text(_TOY + textwrap.dedent(extra))
    return str(path)


def toy_circuit() -> Circuit:
    return Circuit.from_toml(_write_toy())


def levels(circuit, seed=1, n=50):
    sim = circuit.build(minimal_world(1), seed).run(n)
    table = sim.episodes()
    return table["level"].to_numpy(), table["own_draw"].to_numpy()


def test_drugs_act_on_the_released_level():
    base, draws = levels(toy_circuit())
    np.testing.assert_array_equal(base, np.arange(1, 51))
    clamped, _ = levels(toy_circuit().lesion("T", "clamp", level=0.25))
    np.testing.assert_array_equal(clamped, 0.25)
    scaled, _ = levels(toy_circuit().lesion("T", "scale", factor=0.5))
    np.testing.assert_array_equal(scaled, 0.5 * base)
    noisy, noisy_draws = levels(toy_circuit().lesion("T", "noise", sd=2.0))
    residual = noisy - base
    assert abs(residual.mean()) < 3 * 2.0 / np.sqrt(50) and 1.2 < residual.std() < 2.8
    np.testing.assert_array_equal(noisy_draws, draws)  # the region's own stream is untouched
    again, _ = levels(toy_circuit().lesion("T", "noise", sd=2.0))
    np.testing.assert_array_equal(again, noisy)  # deterministic by seed


def test_drugs_compose_in_order():
    both, _ = levels(toy_circuit().lesion("T", "scale", factor=3.0).lesion("T", "clamp", level=1.0))
    np.testing.assert_array_equal(both, 1.0)
    other, _ = levels(toy_circuit().lesion("T", "clamp", level=1.0).lesion("T", "scale", factor=3.0))
    np.testing.assert_array_equal(other, 3.0)


def test_drugs_from_toml_and_recorded_in_the_resolved_circuit():
    path = _write_toy("""
        [[lesion]]
        region = "T"
        how = "clamp"
        level = 7.5
    """)
    circuit = Circuit.from_toml(path)
    np.testing.assert_array_equal(levels(circuit)[0], 7.5)
    assert circuit.to_dict()["lesions"] == [{"region": "T", "how": "clamp", "level": 7.5}]
    assert circuit.lesions == (("T", "clamp", {"level": 7.5}),)
    assert "T (clamp, level=7.5)" in circuit.schedule()


@pytest.mark.parametrize("extra, key, expected", [
    ('how = "clamp"\nlevel = "high"', "lesion[0].level", "number"),
    ('how = "scale"\nfactor = -1.0', "lesion[0].factor", ">= 0"),
    ('how = "noise"\nsd = 0.0', "lesion[0].sd", "> 0"),
    ('how = "noise"', "lesion[0].sd", "positive"),
    ('how = "clamp"\nfactor = 2.0', "lesion[0].factor", "a parameter of Clamp"),
    ('how = "sedate"', "lesion[0].how", "clamp, scale, noise"),
])
def test_bad_drugs_name_the_key(extra, key, expected):
    path = _write_toy('[[lesion]]\nregion = "T"\n' + extra + "\n")
    with pytest.raises(ConfigError) as info:
        Circuit.from_toml(path)
    assert info.value.key == key and expected in str(info.value) and path in str(info.value)


def test_drugs_need_a_neuromodulator_region():
    with pytest.raises(ConfigError, match=r"a lesion of toy.sink \(off\)"):
        toy_circuit().lesion("S", "clamp", level=1.0)
    with pytest.raises(ConfigError, match="no further keys"):
        toy_circuit().lesion("S", "off", level=1.0)


def test_drug_objects():
    assert Clamp(level=2.0).apply(5.0, None) == 2.0
    assert Scale(factor=0.5).apply(5.0, None) == 2.5
    assert Noise(sd=1.0).apply(5.0, np.random.default_rng(0)) == 5.0 + np.random.default_rng(0).standard_normal()
    with pytest.raises(ConfigError):
        Clamp()
