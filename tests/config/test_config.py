"""ConfigError formatting, typed parameters (plain, composite and learner-derived) and TOML helpers."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pytest

from neurocur.config import (
    ConfigError,
    ParamSpec,
    check_params,
    coerce_params,
    make_params,
    param,
    param_specs,
    params_to_dict,
    spec_param,
)
from neurocur.learn.ccipca import AmnesicSchedule
from neurocur.learn.incsfa import IncSFA
from neurocur.learn.lspi import LSPI
from neurocur.learn.roc import MIN_WEIGHT, ROCBank
from neurocur.regions.ec import ECParams
from neurocur.regions.hpc import HPCParams
from neurocur.regions.pfc import PFCParams
from neurocur.tables import check_keys, deep_merge, load_toml, require


@dataclass(frozen=True)
class P:
    rate: float = param(0.5, float, low=0.0, high=1.0, low_open=True)
    count: int = param(3, int, low=1)
    mode: str = param("a", str, choices=("a", "b"))
    gamma: float | str = param(4.0, float, low=0.0, low_open=True, choices=("auto",))
    cut: float | None = param(None, float, low=0.0, optional=True)
    flag: bool = param(True, bool)

    def __post_init__(self):
        check_params(self)


def test_message_format_and_relocation():
    err = ConfigError("exp.toml", "runs.seed", "an integer >= 0", "-1 (int)")
    assert str(err) == "exp.toml: key 'runs.seed': expected an integer >= 0, got -1 (int)"
    assert isinstance(err, ValueError)
    moved = err.relocated("other.toml", "conditions.a")
    assert str(moved) == "other.toml: key 'conditions.a.runs.seed': expected an integer >= 0, got -1 (int)"
    assert str(ConfigError("f.toml", None, "valid TOML", "junk")) == "f.toml: expected valid TOML, got junk"


@pytest.mark.parametrize("field, value, expected", [
    ("rate", 0.0, "a number > 0 and <= 1"),
    ("rate", 1.5, "a number > 0 and <= 1"),
    ("rate", True, "a number > 0 and <= 1"),
    ("rate", float("nan"), "a number > 0 and <= 1"),
    ("count", 2.0, "an integer >= 1"),
    ("count", 0, "an integer >= 1"),
    ("mode", "c", "one of 'a', 'b'"),
    ("gamma", "manual", "a number > 0 or 'auto'"),
    ("cut", -1.0, "a number >= 0 or None (omit the key)"),
    ("flag", "yes", "a boolean (true/false)"),
])
def test_param_errors_name_field_and_expectation(field, value, expected):
    with pytest.raises(ConfigError) as err:
        P(**{field: value})
    assert str(err.value) == f"P: key '{field}': expected {expected}, got {value!r} ({type(value).__name__})"


def test_param_coercion_and_make_params():
    p = P(rate=1, gamma="auto", cut=None)
    assert p.rate == 1.0 and isinstance(p.rate, float) and p.gamma == "auto"
    assert params_to_dict(p) == {"rate": 1.0, "count": 3, "mode": "a", "gamma": "auto", "flag": True}
    with pytest.raises(ConfigError, match=r"^c.toml: key 'regions.X.params.count': expected an integer >= 1, got 0"):
        make_params(P, {"count": 0}, source="c.toml", prefix="regions.X.params")
    with pytest.raises(ConfigError, match=r"key 'regions.X.params.cout': expected a parameter of P \(rate, count"):
        make_params(P, {"cout": 1}, source="c.toml", prefix="regions.X.params")


def test_table_helpers(tmp_path):
    with pytest.raises(ConfigError, match="key 'a.b': expected one of the keys \\['c'\\], got an unknown key"):
        check_keys({"b": 1}, ["c"], source="f", prefix="a")
    with pytest.raises(ConfigError, match="key 'a.c': expected this key to be present, got nothing"):
        check_keys({}, ["c"], source="f", prefix="a", required=["c"])
    assert require({"n": 3}, "n", int, source="f", expected="an int") == 3
    with pytest.raises(ConfigError, match="key 'n': expected an int, got True \\(bool\\)"):
        require({"n": True}, "n", int, source="f", expected="an int")
    assert require({}, "n", int, source="f", expected="an int", default=7) == 7
    assert deep_merge({"a": {"x": 1, "y": 2}, "b": 1}, {"a": {"y": 3}, "c": 4}) == {"a": {"x": 1, "y": 3}, "b": 1, "c": 4}
    bad = tmp_path / "bad.toml"
    bad.write_text("a = [1,\n")
    with pytest.raises(ConfigError, match=f"^{bad}: expected valid TOML, got a syntax error"):
        load_toml(bad)
    with pytest.raises(ConfigError, match="expected an existing TOML file, got no such file"):
        load_toml(tmp_path / "missing.toml")


# --------------------------------------------------------------------------- composite kinds


@dataclass(frozen=True)
class Scene:
    arm_length: float = param(1.0, float, low=0.0, low_open=True)
    n_arms: int = param(2, int, low=1)

    def __post_init__(self):
        check_params(self)


@dataclass(frozen=True)
class W:
    scene: Scene = spec_param(Scene(), ParamSpec.nested(Scene))
    points: tuple = spec_param((0.0, 1.0), ParamSpec.sequence(ParamSpec(float, low=0.0), length=2))
    names: tuple = spec_param(("a",), ParamSpec.sequence(ParamSpec(str, choices=("a", "b")), min_length=1))
    weights: dict = spec_param({"a": 1.0}, ParamSpec.table(ParamSpec(float, low=0.0)))
    rooms: dict = spec_param({}, ParamSpec.table(ParamSpec.nested(Scene)))
    extra: tuple | None = spec_param(None, ParamSpec.sequence(ParamSpec(int), optional=True))

    def __post_init__(self):
        check_params(self)


@pytest.mark.parametrize("table, key, expected, got", [
    ({"scene": {"arm_length": 0}}, "scene.arm_length", "a number > 0", "0 (int)"),
    ({"scene": {"arm": 1}}, "scene.arm", "a parameter of Scene (arm_length, n_arms)", "an unknown parameter"),
    ({"scene": 3}, "scene", "a table of Scene parameters", "3 (int)"),
    ({"points": [1.0]}, "points", "a list of 2 items, each a number >= 0", "[1.0] (list)"),
    ({"points": "ab"}, "points", "a list of 2 items, each a number >= 0", "'ab' (str)"),
    ({"points": [1.0, -1]}, "points[1]", "a number >= 0", "-1 (int)"),
    ({"names": []}, "names", "a list of at least 1 item, each one of 'a', 'b'", "[] (list)"),
    ({"names": ["a", "c"]}, "names[1]", "one of 'a', 'b'", "'c' (str)"),
    ({"weights": {"a": -1}}, "weights.a", "a number >= 0", "-1 (int)"),
    ({"weights": {"": 1}}, "weights", "a table whose names are non-empty strings", "the name ''"),
    ({"weights": [1]}, "weights", "a table of named items, each a number >= 0", "[1] (list)"),
    ({"rooms": {"hall": {"n_arms": 0}}}, "rooms.hall.n_arms", "an integer >= 1", "0 (int)"),
    ({"rooms": {"hall": []}}, "rooms.hall", "a table of Scene parameters", "[] (list)"),
    ({"extra": [1, 2.5]}, "extra[1]", "an integer", "2.5 (float)"),
])
def test_composite_errors_name_the_nested_key(table, key, expected, got):
    with pytest.raises(ConfigError) as err:
        make_params(W, table, source="w.toml", prefix="world.params")
    assert str(err.value) == f"w.toml: key 'world.params.{key}': expected {expected}, got {got}"
    assert (err.value.source, err.value.key, err.value.expected) == ("w.toml", f"world.params.{key}", expected)


def test_composite_errors_from_python():
    with pytest.raises(ConfigError, match=r"^W: key 'rooms.x.arm_length': expected a number > 0, got -1.0 \(float\)$"):
        W(rooms={"x": {"arm_length": -1.0}})
    with pytest.raises(ConfigError, match=r"^W: key 'points\[0\]': expected a number >= 0, got nan"):
        W(points=(float("nan"), 1.0))


def test_composite_coercion_and_round_trip():
    w = make_params(W, {"points": [1, 2], "names": ("b", "a"), "rooms": {"hall": {"arm_length": 2}}, "extra": [3]},
                    source="w.toml", prefix="")
    assert w.points == (1.0, 2.0) and all(isinstance(p, float) for p in w.points)
    assert w.names == ("b", "a") and w.extra == (3,)
    assert w.rooms == {"hall": Scene(arm_length=2.0)} and w.scene == Scene()
    plain = params_to_dict(w)
    assert plain == {"scene": {"arm_length": 1.0, "n_arms": 2}, "points": [1.0, 2.0], "names": ["b", "a"],
                     "weights": {"a": 1.0}, "rooms": {"hall": {"arm_length": 2.0, "n_arms": 2}}, "extra": [3]}
    assert make_params(W, plain, source="w.toml", prefix="") == w
    assert "extra" not in params_to_dict(W())
    inner = Scene(n_arms=3)
    assert W(scene=inner).scene is inner  # an instance passes unchanged
    assert W().weights is not W().weights  # a table default is copied


def test_spec_kinds_and_classes():
    with pytest.raises(TypeError):
        ParamSpec(tuple)  # a sequence needs an item spec
    with pytest.raises(TypeError):
        ParamSpec(float, item=ParamSpec(float))
    with pytest.raises(TypeError):
        ParamSpec(list, item=ParamSpec(float))
    spec = ParamSpec(float, low=0.0, classes=(Scene,))
    scene = Scene()
    assert spec.coerce(scene) is scene and spec.coerce(2) == 2.0
    with pytest.raises(ConfigError, match=r"^f: key 'k': expected a number >= 0 or a Scene, got \{\} \(dict\)$"):
        spec.coerce({}, source="f", key="k")
    assert coerce_params({"n": ParamSpec(int, low=1)}, {"n": np.int64(3)}, source="f") == {"n": 3}
    with pytest.raises(ConfigError, match=r"^f: key 'n': expected an integer >= 1, got 0 \(int\)$"):
        coerce_params({"n": ParamSpec(int, low=1)}, {"n": 0}, source="f")


def test_param_specs_lists_the_fields_that_carry_a_spec_in_order():
    @dataclass
    class Mixed:
        size: int = param(2, int, low=1)
        label: str = "plain"  # no spec: not a parameter checked by one
        rate: float = spec_param(0.5, ParamSpec(float, low=0.0))

    specs = param_specs(Mixed)
    assert list(specs) == ["size", "rate"] and specs["size"].low == 1
    assert param_specs(Mixed()) is specs  # a class or an instance, computed once per class
    with pytest.raises(TypeError):
        specs["size"] = ParamSpec(int)  # read-only
    assert list(param_specs(P)) == ["rate", "count", "mode", "gamma", "cut", "flag"]


# --------------------------------------------------------------------------- region parameters from learners

DERIVED = [
    (ECParams, "n_components", IncSFA, "n_components"),
    (ECParams, "n_pca", IncSFA, "n_pca"),
    (ECParams, "amnesic", IncSFA, "amnesic"),
    (ECParams, "var_fraction", IncSFA, "var_fraction"),
    (ECParams, "eig_cutoff", IncSFA, "eig_cutoff"),
    (ECParams, "mca_rate", IncSFA, "mca_rate"),
    (ECParams, "gamma", IncSFA, "gamma"),
    (HPCParams, "max_clusters", ROCBank, "max_clusters"),
    (HPCParams, "amnesic", ROCBank, "amnesic"),
    (HPCParams, "width", ROCBank, "width"),
    (HPCParams, "prune_min_weight", ROCBank, "min_weight"),
    (PFCParams, "discount", LSPI, "discount"),
]
P2 = np.array([[[1.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [1.0, 0.0]]])
LEARNER_CALLS = {
    IncSFA: lambda name, value: IncSFA(**{name: value}),
    ROCBank: lambda name, value: (ROCBank(3, 2).prune(value) if name == "min_weight"
                                  else ROCBank(3, 2, **{name: value})),
    LSPI: lambda name, value: LSPI(P2, **{name: value}),
}
PROBES = [-1, -1e-9, 0, 0.0, 1e-9, 0.05, 0.5, 0.5000001, 0.6, 0.999, 1, 1.0, 1.0000001, 1.5, 2, 2.5, 3, 4, 4.0,
          100, "auto", "x", None, True, float("nan"), float("inf"), AmnesicSchedule()]


def _accepts(call) -> bool:
    try:
        call()
    except ValueError:
        return False
    return True


@pytest.mark.parametrize("region, field, learner, name", DERIVED)
def test_region_parameter_takes_the_learner_spec(region, field, learner, name):
    spec = next(f.metadata["spec"] for f in dataclasses.fields(region) if f.name == field)
    assert spec is (MIN_WEIGHT if (learner, name) == (ROCBank, "min_weight") else param_specs(learner)[name])


@pytest.mark.parametrize("region, field, learner, name", DERIVED)
def test_region_rejects_exactly_what_the_learner_rejects(region, field, learner, name):
    for value in PROBES:
        region_ok = _accepts(lambda v=value: region(**{field: v}))
        assert region_ok == _accepts(lambda v=value: LEARNER_CALLS[learner](name, v)), value


def test_former_ec_drift_closed():
    with pytest.raises(ConfigError, match=r"^ECParams: key 'mca_rate': expected a number > 0 and <= 0.5, got 0.6"):
        ECParams(mca_rate=0.6)
    with pytest.raises(ConfigError, match=r"^ECParams: key 'eig_cutoff': expected a number >= 0 and < 1, got 1.0"):
        ECParams(eig_cutoff=1.0)
    assert ECParams(mca_rate=0.5, eig_cutoff=0.999).mca_rate == 0.5
    with pytest.raises(ConfigError, match=r"key 'regions.EC.params.mca_rate': expected a number > 0 and <= 0.5"):
        make_params(ECParams, {"mca_rate": 0.75}, source="c.toml", prefix="regions.EC.params")
