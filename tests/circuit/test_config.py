"""ConfigError formatting, typed parameters and TOML helpers."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from neurocur.config import (ConfigError, check_keys, check_params, deep_merge, load_toml, make_params, param,
                             params_to_dict, require)


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
