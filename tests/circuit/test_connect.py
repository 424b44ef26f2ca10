"""Edges from Python: Circuit.connect and Circuit.replace(..., inputs=...) build what a variant
circuit file's [[edges]] and [replace.NAME] tables build."""

from __future__ import annotations

import pandas as pd
import pytest

from neurocur.circuit import Circuit
from neurocur.config import ConfigError

SLOWNESS_VTA = {"type": "vta.slowness_progress", "params": {"boredom": -100.0}}


def edges(circuit: Circuit) -> set[tuple]:
    return {(e["from"], e["signal"], e["to"], e["input"], e["delayed"]) for e in circuit.to_dict()["edges"]}


def test_replace_with_inputs_builds_the_variant_file():
    """vta_slowness_progress.toml replaces the VTA and adds the edge into its new input."""
    built = Circuit.from_toml("cd_misfa").replace("VTA", SLOWNESS_VTA, inputs={"progress": "EC.slowness_progress"})
    shipped = Circuit.from_toml("vta_slowness_progress")
    assert built.to_dict()["regions"] == shipped.to_dict()["regions"]
    assert edges(built) == edges(shipped)
    assert ("EC", "slowness_progress", "VTA", "progress", False) in edges(built)


def test_a_new_input_without_an_edge_is_an_error_naming_it():
    with pytest.raises(ConfigError, match="progress"):
        Circuit.from_toml("cd_misfa").replace("VTA", SLOWNESS_VTA)


def test_the_circuit_built_in_python_runs_as_the_file_does(make_world, small):
    built = (Circuit.from_toml("cd_misfa", overrides=small)
             .replace("VTA", SLOWNESS_VTA, inputs={"progress": "EC.slowness_progress"}))
    a = built.build(make_world(), seed=5).run(20 * 120).episodes()
    b = Circuit.from_toml("vta_slowness_progress", overrides=small).build(make_world(), seed=5).run(20 * 120).episodes()
    assert a["da"].notna().any() and a["da"].abs().sum() > 0
    pd.testing.assert_frame_equal(a, b)


def test_connect_rewires_an_input_in_place():
    """The slowness VTA fed by HPC's state-by-state progress instead of EC's slowness progress:
    the edge into VTA.progress is replaced where it was, and EC's optional output is then unread."""
    shipped = Circuit.from_toml("vta_slowness_progress")
    rewired = shipped.connect("HPC.progress", "VTA.progress")
    assert len(rewired.links) == len(shipped.links)
    assert ("HPC", "progress", "VTA", "progress", False) in edges(rewired)
    assert not any(k.signal == "slowness_progress" for k in rewired.links)
    assert [str(k) for k in rewired.links].index("HPC.progress -> VTA.progress") == \
        [str(k) for k in shipped.links].index("EC.slowness_progress -> VTA.progress")


@pytest.mark.parametrize("source, target, match", [
    ("EC", "VTA.progress", r"'REGION\.port' naming an output"),
    ("EC.slowness_progress", "VTA", r"'REGION\.port' naming an input"),
    ("EC.nothing", "VTA.progress", r"connect\.signal.*an output of region 'EC'"),
    ("EC.slowness_progress", "VTA.nothing", r"connect\.input.*an input of region 'VTA'"),
    ("XX.y", "VTA.progress", r"connect\.from.*a declared region"),
])
def test_connect_names_what_is_wrong(source, target, match):
    with pytest.raises(ConfigError, match=match):
        Circuit.from_toml("vta_slowness_progress").connect(source, target)
