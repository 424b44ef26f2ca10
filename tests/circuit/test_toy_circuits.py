"""Toy regions registered here: wiring, scheduling, delayed and learn-phase edges, validation."""

from __future__ import annotations

import textwrap
from dataclasses import dataclass
from importlib.metadata import EntryPoint

import numpy as np
import pandas as pd
import pytest

from neurocur import registry
from neurocur.circuit import Circuit
from neurocur.config import ConfigError, check_params, param
from neurocur.regions import REGIONS
from neurocur.regions.base import Probe, Region, Signal


@dataclass(frozen=True)
class GainParams:
    gain: float = param(2.0, float, low=0.0, low_open=True)

    def __post_init__(self):
        check_params(self)


@REGIONS.register("toy.ramp")
class Ramp(Region):
    """x = index of the pass (0, 1, 2, ...)."""

    outputs = (Signal("x", "float64", ()),)
    probes = (Probe("x", "float", "a.u."),)

    def reset(self, rng):
        self.k = -1

    def step(self):
        self.k += 1
        return (float(self.k),)

    def record(self):
        return (float(self.k),)


@REGIONS.register("toy.gain")
class Gain(Region):
    """y = gain * x."""

    Params = GainParams
    inputs = (Signal("x", "float64", ()),)
    outputs = (Signal("y", "float64", ()),)
    probes = (Probe("y", "float", "a.u."),)

    def step(self, x):
        self.y = self.params.gain * x
        return (self.y,)

    def record(self):
        return (self.y,)


@REGIONS.register("toy.acc")
class Acc(Region):
    """total = previous total (delayed self-edge, None at first) + y + w."""

    inputs = (Signal("y", "float64", ()), Signal("w", "float64", ()), Signal("prev", "float64", ()))
    outputs = (Signal("total", "float64", ()),)
    probes = (Probe("total", "float", "a.u."),)

    def step(self, y, w, prev):
        self.total = (0.0 if prev is None else prev) + y + w
        return (self.total,)

    def record(self):
        return (self.total,)


@REGIONS.register("toy.learner")
class Learner(Region):
    """Step: w = number of learn calls so far. Learn: remembers this pass's total (a later region)."""

    inputs = (Signal("x", "float64", ()),)
    learn_inputs = (Signal("total", "float64", ()),)
    outputs = (Signal("w", "float64", ()),)
    frame_probes = (Probe("seen", "float", "a.u."),)

    def reset(self, rng):
        self.seen = []

    def step(self, x):
        return (float(len(self.seen)),)

    def learn(self, total):
        self.seen.append(total)

    def record_frames(self):
        return np.array([[self.seen[-1]], [self.seen[-1] + 0.5]])


@REGIONS.register("toy.vec3")
class Vec3(Region):
    outputs = (Signal("v", "float64", (3,)),)

    def step(self):
        return (np.ones(3),)


@REGIONS.register("toy.vec4sink")
class Vec4Sink(Region):
    inputs = (Signal("v", "float64", (4,)),)


@REGIONS.register("toy.relay")
class Relay(Region):
    inputs = (Signal("a", "float64", ()),)
    outputs = (Signal("b", "float64", ()),)

    def step(self, a):
        return (0.0 if a is None else a,)


TOY = """
[regions.learner]
type = "toy.learner"

[regions.acc]
type = "toy.acc"

[regions.dbl]
type = "toy.gain"
params = { gain = 2.0 }

[regions.src]
type = "toy.ramp"

[[edges]]
from = "src"
signal = "x"
to = "dbl"

[[edges]]
from = "src"
signal = "x"
to = "learner"

[[edges]]
from = "dbl"
signal = "y"
to = "acc"

[[edges]]
from = "learner"
signal = "w"
to = "acc"

[[edges]]
from = "acc"
signal = "total"
to = "acc"
input = "prev"
delayed = true

[[edges]]
from = "acc"
signal = "total"
to = "learner"
"""


def write(tmp_path, text, name="toy.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_toy_circuit_outputs_by_hand(tmp_path):
    circuit = Circuit.from_toml(write(tmp_path, TOY))
    assert circuit.step_order == ("src", "learner", "dbl", "acc")  # declaration order breaks ties
    assert circuit.learn_order == ("learner",)
    sim = circuit.build(None, seed=0).run(5)
    # pass k: y = 2k, w = k (learn calls before this pass), total_k = total_{k-1} + 3k
    totals = np.cumsum([3.0 * k for k in range(5)])
    np.testing.assert_array_equal(sim.regions["learner"].seen, totals)  # learn reads THIS pass's total
    table = sim.episodes()
    assert list(table.columns) == ["episode", "step", "x", "y", "total"]
    np.testing.assert_array_equal(table["total"], totals)
    np.testing.assert_array_equal(table["y"], 2.0 * np.arange(5))
    np.testing.assert_array_equal(table["step"], np.arange(5))  # no clock region: one step per pass
    assert sim.n_episodes == 5 and sim.n_frames == 5
    sim.run(2)  # continues
    assert sim.episodes()["total"].iloc[-1] == totals[-1] + 15 + 18


def test_schedule_printout(tmp_path):
    text = Circuit.from_toml(write(tmp_path, TOY)).schedule()
    assert text.splitlines() == [
        "step order:",
        "  1. src [toy.ramp]",
        "  2. learner [toy.learner]  reads x<-src.x",
        "  3. dbl [toy.gain]  reads x<-src.x",
        "  4. acc [toy.acc]  reads y<-dbl.y, w<-learner.w, prev<-acc.total (delayed)",
        "learn order: learner",
        "delayed edges (previous pass):",
        "  acc.total -> acc.prev",
        "learn-phase edges (this pass, after all steps):",
        "  acc.total -> learner.total",
    ]


def test_probes_tidy_table_matches_wide(tmp_path):
    sim = Circuit.from_toml(write(tmp_path, TOY)).build(None, seed=0, record_frames=True).run(4)
    wide, long = sim.episodes(), sim.probes()
    assert list(long.columns) == ["episode", "step", "region", "signal", "value"]
    tot = long[(long.region == "acc") & (long.signal == "total")]
    np.testing.assert_array_equal(tot["value"], wide["total"])
    frames = long[long.signal == "seen"]
    assert len(frames) == 8  # two frame rows per pass
    np.testing.assert_array_equal(frames["value"].to_numpy()[::2], wide["total"])
    np.testing.assert_array_equal(frames["step"].to_numpy()[:4], [0, 1, 1, 2])


def test_python_api_replace_and_lesion(tmp_path):
    circuit = Circuit.from_toml(write(tmp_path, TOY))
    tripled = circuit.replace("dbl", Gain("dbl", gain=3.0))
    assert circuit.specs["dbl"].params.gain == 2.0  # the original is unchanged
    sim = tripled.build(None, seed=0).run(3)
    np.testing.assert_array_equal(sim.episodes()["y"], [0.0, 3.0, 6.0])
    spec = circuit.replace("dbl", {"type": "toy.gain", "params": {"gain": 5.0}})
    np.testing.assert_array_equal(spec.build(None, 0).run(2).episodes()["y"], [0.0, 5.0])
    again = circuit.with_params({"dbl.gain": 4.0})
    np.testing.assert_array_equal(again.build(None, 0).run(2).episodes()["y"], [0.0, 4.0])
    with pytest.raises(ConfigError, match="a lesion of toy.gain"):
        circuit.lesion("dbl", how="random")
    with pytest.raises(ValueError, match="no region named 'nope'"):
        circuit.lesion("nope", how="random")


def test_delayed_edge_breaks_cycle_and_missing_delay_is_named(tmp_path):
    loop = """
    [regions.a]
    type = "toy.relay"
    [regions.b]
    type = "toy.relay"
    [[edges]]
    from = "a"
    signal = "b"
    to = "b"
    input = "a"
    [[edges]]
    from = "b"
    signal = "b"
    to = "a"
    input = "a"
    """
    path = write(tmp_path, loop)
    with pytest.raises(ConfigError) as err:
        Circuit.from_toml(path)
    assert str(err.value).startswith(f"{path.resolve()}: key 'edges': expected")
    assert "cycle a -> b -> a has no delayed edge" in str(err.value)
    ok = Circuit.from_toml(write(tmp_path, loop + "    delayed = true\n", "ok.toml"))
    assert ok.step_order == ("a", "b")  # b -> a is delayed; a -> b orders the step


def _expect(tmp_path, text, *fragments):
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as err:
        Circuit.from_toml(path)
    message = str(err.value)
    assert message.startswith(str(path.resolve())), message
    for f in fragments:
        assert f in message, message
    return message


def test_unknown_region_type(tmp_path):
    _expect(tmp_path, TOY.replace('type = "toy.ramp"', 'type = "toy.rampp"'),
            "key 'regions.src.type'", "expected a registered region type", "toy.ramp,", "got 'toy.rampp' (str)")


def test_missing_input(tmp_path):
    text = TOY.replace('[[edges]]\nfrom = "dbl"\nsignal = "y"\nto = "acc"\n', "")
    _expect(tmp_path, text, "key 'regions.acc'", "expected an edge into its input 'y' (float64 shape ())", "got no edge")


def test_output_that_goes_nowhere(tmp_path):
    text = """
    [regions.src]
    type = "toy.ramp"
    [regions.dbl]
    type = "toy.gain"
    [[edges]]
    from = "src"
    signal = "x"
    to = "dbl"
    """
    _expect(tmp_path, text, "key 'regions.dbl'", "expected an edge from its output 'y' (float64 shape ())",
            "got an output that goes nowhere")


def test_shape_mismatch(tmp_path):
    text = """
    [regions.v]
    type = "toy.vec3"
    [regions.s]
    type = "toy.vec4sink"
    [[edges]]
    from = "v"
    signal = "v"
    to = "s"
    """
    _expect(tmp_path, text, "key 'edges[0]'", "expected s.v as float64 shape (4,)", "got v.v as float64 shape (3,)")


def test_dtype_mismatch(tmp_path):
    text = TOY.replace('to = "acc"\ninput = "prev"', 'to = "dbl"\ninput = "x"')
    # dbl.x now has two edges: the second is reported
    _expect(tmp_path, text, "expected a single edge into input 'dbl.x'")


def test_bad_parameter_type_and_range(tmp_path):
    _expect(tmp_path, TOY.replace("gain = 2.0", 'gain = "two"'),
            "key 'regions.dbl.params.gain'", "expected a number > 0", "got 'two' (str)")
    _expect(tmp_path, TOY.replace("gain = 2.0", "gain = -1.0"),
            "key 'regions.dbl.params.gain'", "expected a number > 0", "got -1.0 (float)")
    _expect(tmp_path, TOY.replace("gain = 2.0", "gian = 1.0"),
            "key 'regions.dbl.params.gian'", "a parameter of GainParams (gain)", "got an unknown parameter")


def test_bad_edges_and_keys(tmp_path):
    _expect(tmp_path, TOY.replace('from = "dbl"', 'from = "dbll"'), "key 'edges[2].from'", "got 'dbll' (str)")
    _expect(tmp_path, TOY.replace('signal = "y"', 'signal = "z"'), "key 'edges[2].signal'",
            "expected an output of region 'dbl' (y)")
    _expect(tmp_path, TOY.replace('input = "prev"', 'input = "prevv"'), "key 'edges[4].input'")
    _expect(tmp_path, TOY.replace("delayed = true", 'delayed = "yes"'), "key 'edges[4].delayed'", "expected true or false")
    _expect(tmp_path, TOY + "\n[regoins.x]\n", "key 'regoins'", "got an unknown key")
    _expect(tmp_path, "[regions.a\n", "expected valid TOML")


def test_overrides_name_the_key(tmp_path):
    path = write(tmp_path, TOY)
    with pytest.raises(ConfigError, match=r"^overrides: key 'dbl.gain': expected a number > 0, got 0 \(int\)$"):
        Circuit.from_toml(path, overrides={"dbl.gain": 0})
    with pytest.raises(ConfigError, match="key 'nope.gain'"):
        Circuit.from_toml(path, overrides={"nope.gain": 1.0})
    c = Circuit.from_toml(path, overrides={"dbl.gain": 3})
    assert c.specs["dbl"].params.gain == 3.0 and isinstance(c.specs["dbl"].params.gain, float)


def test_extends_replace_and_loop(tmp_path):
    write(tmp_path, TOY, "base.toml")
    child = write(tmp_path, 'extends = "base.toml"\n[replace.dbl]\ntype = "toy.gain"\nparams = { gain = 7.0 }\n', "child.toml")
    sim = Circuit.from_toml(child).build(None, 0).run(2)
    np.testing.assert_array_equal(sim.episodes()["y"], [0.0, 7.0])
    merged = write(tmp_path, 'extends = "base.toml"\n[regions.dbl.params]\ngain = 0.5\n', "merged.toml")
    assert Circuit.from_toml(merged).specs["dbl"].params.gain == 0.5
    write(tmp_path, 'extends = "b.toml"\n', "a.toml")
    write(tmp_path, 'extends = "a.toml"\n', "b.toml")
    with pytest.raises(ConfigError, match="a chain of circuit files without a loop, got a.toml -> b.toml -> a.toml"):
        Circuit.from_toml(tmp_path / "a.toml")


def test_same_seed_same_tables(tmp_path):
    circuit = Circuit.from_toml(write(tmp_path, TOY))
    a = circuit.build(None, seed=5).run(6)
    b = circuit.build(None, seed=5).run(6)
    pd.testing.assert_frame_equal(a.episodes(), b.episodes())
    pd.testing.assert_frame_equal(a.probes(), b.probes())


def test_plugin_region_from_entry_point(tmp_path, monkeypatch):
    (tmp_path / "neurocur_toy_plugin.py").write_text(textwrap.dedent("""
        from neurocur.regions.base import Region, Signal

        class Negate(Region):
            inputs = (Signal("x", "float64", ()),)
            outputs = (Signal("y", "float64", ()),)

            def step(self, x):
                return (-x,)
    """))
    monkeypatch.syspath_prepend(str(tmp_path))
    ep = EntryPoint(name="plugin.negate", value="neurocur_toy_plugin:Negate", group=REGIONS.group)
    monkeypatch.setattr(registry, "entry_points", lambda group: [ep] if group == REGIONS.group else [])
    monkeypatch.delitem(REGIONS._types, "plugin.negate", raising=False)
    assert "plugin.negate" in REGIONS.names()
    path = write(tmp_path, TOY.replace('type = "toy.gain"\nparams = { gain = 2.0 }', 'type = "plugin.negate"'))
    sim = Circuit.from_toml(path).build(None, 0).run(3)
    np.testing.assert_array_equal(sim.episodes()["total"], [0.0, -1.0 + 1.0, -2.0 + 2.0])
    assert REGIONS.get("plugin.negate").type_name == "plugin.negate"
    with pytest.raises(registry.UnknownType):
        REGIONS.get("plugin.absent")


def test_register_rejects_a_second_class_under_a_taken_name():
    with pytest.raises(ValueError, match="already registered"):
        @REGIONS.register("toy.gain")
        class Other(Region):
            pass


def test_step_returning_wrong_arity_is_caught(tmp_path):
    @REGIONS.register("toy.broken")
    class Broken(Region):
        outputs = (Signal("x", "float64", ()),)

        def step(self):
            return (1.0, 2.0)

    text = TOY.replace('type = "toy.ramp"', 'type = "toy.broken"')
    with pytest.raises(ValueError, match="region 'src' step\\(\\) returned 2 values for 1 declared outputs"):
        Circuit.from_toml(write(tmp_path, text)).build(None, 0).run(1)
