"""Provenance beyond the package: plug-ins loaded from entry points, and a clone that moved."""

import importlib
import sys
from pathlib import Path

import pytest

from neurocur.experiments import load_experiment
from neurocur.regions.base import REGIONS
from neurocur.results import ResultsError, ResultsStore, fingerprint

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"

PLUGIN = "class Plugged:\n    dose = {dose}\n"


@pytest.fixture
def plugin(tmp_path, monkeypatch):
    """A distribution ``plugged 1.0`` whose module registers region type ``plugged.region``."""
    site = tmp_path / "site"
    info = site / "plugged-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: plugged\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[neurocur.regions]\nplugged.region = plugged_mod:Plugged\n")
    (info / "RECORD").write_text("plugged_mod.py,,\nplugged-1.0.dist-info/METADATA,,\n")
    module = site / "plugged_mod.py"
    module.write_text(PLUGIN.format(dose=0.25))
    monkeypatch.syspath_prepend(str(site))
    importlib.invalidate_caches()
    yield module
    REGIONS._types.pop("plugged.region", None)
    sys.modules.pop("plugged_mod", None)


def test_a_loaded_plugin_is_in_the_code_fingerprint_and_its_change_refuses_a_resume(plugin, tmp_path):
    assert fingerprint.plugin_fingerprints() == []  # installed, not loaded: it computes nothing
    REGIONS.get("plugged.region")
    [found] = fingerprint.code_fingerprint()["plugins"]
    assert (found["entry_point"], found["name"], found["version"]) == ("neurocur.regions:plugged.region",
                                                                        "plugged", "1.0")
    store = ResultsStore(tmp_path / "out")
    config = load_experiment(SYNTHETIC, runs=1, steps=100).resolved()
    (tmp_path / "out").mkdir()
    store.save_config(store.check(config))
    assert store.check(config) is None  # the same code: resumes
    plugin.write_text(PLUGIN.format(dose=0.5))  # the plug-in changed between two resumes
    with pytest.raises(ResultsError, match=r"the code changed .*plug-in plugged 1.0 source \w{8} then, .*"
                                           r"plug-in plugged 1.0 source \w{8} now"):
        store.check(config)
    assert fingerprint.code_fingerprint()["plugins"][0]["source"] != found["source"]


def test_a_moved_clone_resumes_its_own_folder(tmp_path, monkeypatch):
    config = load_experiment(SYNTHETIC, runs=1, steps=100).resolved()
    store = ResultsStore(tmp_path / "out")
    (tmp_path / "out").mkdir()
    store.save_config(store.check(config))
    written = (tmp_path / "out" / "config.toml").read_text()
    assert str(fingerprint.PACKAGE) not in written and '"<neurocur>/circuits/cd_misfa.toml"' in written
    moved = Path("/elsewhere/clone/neurocur")
    monkeypatch.setattr(fingerprint, "PACKAGE", moved)

    def move(tree):
        if isinstance(tree, dict):
            return {k: move(v) for k, v in tree.items()}
        if isinstance(tree, list):
            return [move(v) for v in tree]
        return tree.replace(str(ROOT / "neurocur"), str(moved)) if isinstance(tree, str) else tree

    assert move(config)["experiment"].startswith(str(moved))
    assert store.check(move(config)) is None
