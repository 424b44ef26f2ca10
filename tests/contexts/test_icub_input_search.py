"""The declared search of the iCub scene's input parameters (benchmarks/icub_input_search.py):
its design, the scenes it builds, its targets, its adoption rule and its resumption."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from neurocur.contexts.icub_scene import SceneParams

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "icub_input_search.py"
_spec = importlib.util.spec_from_file_location("icub_input_search", _PATH)
search = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(search)


def test_the_design_is_the_default_then_sobol_points_in_the_declared_ranges():
    plan = search.design(16, 2013)
    assert plan.equals(search.design(16, 2013)) and not plan.equals(search.design(16, 7))
    assert plan.iloc[0, 1:].tolist() == [default for _, _, default in search.PARAMETERS.values()]
    for name, (low, high, _) in search.PARAMETERS.items():
        assert plan[name].between(low, high).all(), name
    assert sorted(plan["steps_per_frame"].iloc[1:].value_counts().tolist()) == [4, 4, 4, 4]  # Sobol: balanced
    # a balanced design puts 8 of 16 points in each half of every continuous range
    for name in ("angle_span", "camera_fovy", "arm_contrast", "blur"):
        low, high, _ = search.PARAMETERS[name]
        assert (plan[name].iloc[1:] < (low + high) / 2).sum() == 8, name


def test_a_design_row_sets_the_arc_about_the_object_and_the_other_fields():
    row = {"scene": 1, "steps_per_frame": 3, "angle_span": 0.5, "camera_fovy": 40.0, "arm_contrast": 0.4, "blur": 2.5}
    params = search.world_params(row, n_episodes=5)
    assert params.scene.angle_first == pytest.approx(-29.8 + 0.5 * (-66.0 + 29.8))  # -47.9
    assert params.scene.angle_last == pytest.approx(-29.8 + 0.5 * (24.0 + 29.8))  # -2.9
    assert (params.scene.camera_fovy, params.scene.arm_contrast, params.protocol.steps_per_frame, params.blur,
            params.n_episodes, params.dataset_seed) == (40.0, 0.4, 3, 2.5, 5, 0)
    default = search.world_params(search.design(1, 0).iloc[0].to_dict())
    assert default.scene == SceneParams() and default.blur == 0


def _row(ot, orr, dt, dr, ct=1.0, cr=1.0, scene=1):
    return {"scene": scene, "omega_topple": ot, "omega_roll": orr, "dims_topple": dt, "dims_roll": dr,
            "contact_topple": ct, "contact_roll": cr}


def test_targets_distance_and_the_adoption_rule_on_a_hand_made_table():
    exact = _row(0.9982, 0.9988, 12.5, 12.5)
    assert search.meets(exact) and search.distance(exact) == 0
    edge = _row(0.99869, 0.99831, 10, 15)  # every number at (or 0.00001 inside) the edge of its band
    assert search.meets(edge) and search.distance(edge) == pytest.approx(np.sqrt(2 * 0.98**2 + 2))
    assert not search.meets(_row(0.99875, 0.9988, 12, 12))  # topple's Omega 0.00055 off
    assert not search.meets(_row(0.9982, 0.9988, 12, 16))  # roll needs 16 dimensions
    assert not search.meets(_row(0.9982, 0.9988, 12, 12, cr=0.9))  # the hand misses the ball too often
    assert search.distance(_row(0.99987, 0.99998, 60, 93)) == pytest.approx(
        np.sqrt((0.00167 / 0.0005) ** 2 + (0.00118 / 0.0005) ** 2 + (47.5 / 2.5) ** 2 + (80.5 / 2.5) ** 2))
    table = pd.DataFrame([_row(0.99987, 0.99998, 60, 93, scene=0), _row(0.9984, 0.9986, 11, 14, scene=1),
                          _row(0.9982, 0.9988, 12, 13, scene=2), _row(0.9982, 0.9988, 12, 13, scene=3),
                          _row(0.9982, 0.9988, 12, 12, ct=0.5, scene=4)])
    assert search.chosen(table) == 2  # nearest the paper; scene 3 ties and comes later; scene 4 misses the cup
    assert search.chosen(table.iloc[[0]]) is None


def test_the_search_writes_every_scene_and_resumes_where_it_stopped(tmp_path):
    calls = []

    def fake(params):
        calls.append(params)
        return {"omega_topple": 0.999, "dims_topple": 12, "contact_topple": 1.0, "length_topple": 90.0,
                "omega_roll": 0.9988, "dims_roll": 14, "contact_roll": 1.0, "length_roll": 80.0}

    out = tmp_path / "search.csv"
    search.search(out, 2, 5, measure_fn=fake)
    assert len(calls) == 3 and len(pd.read_csv(out)) == 3
    pd.read_csv(out).iloc[:2].to_csv(out, index=False)  # as if stopped after scene 1
    table = search.search(out, 2, 5, measure_fn=fake)
    assert len(calls) == 4 and calls[-1].protocol.steps_per_frame == search.design(2, 5)["steps_per_frame"][2]
    assert table["scene"].tolist() == [0, 1, 2] and not table["meets"].any()  # topple's 0.999 is 0.0008 off
    assert table["distance"].tolist() == [pytest.approx(np.sqrt(1.6**2 + 0.2**2 + 0.6**2), abs=1e-4)] * 3
    with pytest.raises(ValueError, match="not those of --n 2 --seed 6"):
        search.search(out, 2, 6, measure_fn=fake)
