"""Shipped circuits and experiments are addressable by name; paths keep working."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.experiments.spec import load_experiment, resolve_experiment, shipped_experiments
from neurocur.tables import shipped_files

PACKAGE = Path(__file__).resolve().parents[2] / "neurocur"


def test_shipped_names():
    assert set(shipped_files("circuit")) == {p.stem for p in (PACKAGE / "circuits").glob("*.toml")}
    assert {"synthetic", "reproduction", "sweep_pfc", "icub", "gym_classic"} <= set(shipped_experiments())


def test_circuit_by_name_equals_by_path(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # names do not depend on the working directory
    by_name = Circuit.from_toml("lesion_lc_random")
    by_path = Circuit.from_toml(PACKAGE / "circuits" / "lesion_lc_random.toml")
    assert by_name.to_dict() == by_path.to_dict() and by_name.lesions == (("LC", "random", {}),)


def test_unknown_circuit_name_lists_the_shipped_ones(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ConfigError, match=r"cd_misfa.*vta_novelty.*'cd_misfo'"):
        Circuit.from_toml("cd_misfo")
    with pytest.raises(ConfigError, match="no such file"):
        Circuit.from_toml("cd_misfo.toml")  # ends with .toml: a path, not a name


def test_extends_a_shipped_name_or_a_path(tmp_path):
    (tmp_path / "mine.toml").write_text('extends = "cd_misfa"\n[[lesion]]\nregion = "LC"\nhow = "random"\n')
    assert Circuit.from_toml(tmp_path / "mine.toml").to_dict() == Circuit.from_toml("lesion_lc_random").to_dict()
    (tmp_path / "local.toml").write_text((PACKAGE / "circuits" / "cd_misfa.toml").read_text())
    (tmp_path / "mine2.toml").write_text('extends = "local.toml"\n')
    assert Circuit.from_toml(tmp_path / "mine2.toml").to_dict() == Circuit.from_toml("cd_misfa").to_dict()
    (tmp_path / "bad.toml").write_text('extends = "nothing_here"\n')
    with pytest.raises(ConfigError) as info:
        Circuit.from_toml(tmp_path / "bad.toml")
    assert info.value.key == "extends" and "cd_misfa" in info.value.expected


def test_a_local_file_wins_over_a_shipped_name(tmp_path):
    """A value that is an existing path is a path, even without .toml."""
    (tmp_path / "cd_misfa").write_text('extends = "lesion_lc_random"\n')
    (tmp_path / "exp.toml").write_text('circuit = "cd_misfa"\nruns = 1\nsteps = 10\n')
    exp = load_experiment(tmp_path / "exp.toml")
    assert exp.conditions["default"].circuit_path == tmp_path / "cd_misfa"
    assert exp.conditions["default"].circuit.lesions == (("LC", "random", {}),)


def test_experiment_by_name_and_its_circuits(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    assert resolve_experiment("synthetic") == PACKAGE / "experiments_data" / "synthetic.toml"
    exp = load_experiment("synthetic", runs=1, steps=100)
    assert exp.conditions["random_switching"].circuit_path == PACKAGE / "circuits" / "lesion_lc_random.toml"
    assert load_experiment("synthetic", sets=["circuit=vta_novelty"]).conditions["curious"].circuit_path == \
        PACKAGE / "circuits" / "vta_novelty.toml"
    with pytest.raises(ConfigError, match=r"shipped experiment \(.*synthetic.*\), got 'synthetc'"):
        load_experiment("synthetc")
    (tmp_path / "e.toml").write_text('circuit = "no_such_circuit"\nruns = 1\nsteps = 10\n')
    with pytest.raises(ConfigError) as info:
        load_experiment("e.toml")
    assert info.value.key == "circuit" and "cd_misfa" in info.value.expected
