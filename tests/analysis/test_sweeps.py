"""Sweep comparisons on hand-made per-run tables: every point against a reference point, every
condition against a reference condition at the same point, paired by run and Holm-adjusted."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest
from neuro_tables import results_of
from statsmodels.stats.multitest import multipletests

from neurocur.analysis import (
    COMPARE_COLUMNS,
    compare,
    compare_to_condition,
    compare_to_point,
    per_run,
    split_condition,
    sweep_columns,
    sweep_points,
)

GAINS = (0.5, 1.0, 2.0)
NORMS = ("global", "image")
RUNS = 12


def _label(gain, norm):
    return f"LC.gain={gain},world.normalise={norm}"


@pytest.fixture(scope="module")
def sweep_runs():
    """A per-run table of a 3 × 2 sweep of two conditions; each run's world adds its own baseline."""
    rng = np.random.default_rng(11)
    baseline = rng.normal(0.0, 3.0, RUNS)
    rows = []
    for condition, gain, norm in itertools.product(("curious", "random_switching"), GAINS, NORMS):
        shift = (gain - 1.0) * 2.0 + (1.0 if condition == "curious" else 0.0)
        noise = rng.normal(0.0, 0.3, RUNS)
        for run in range(RUNS):
            rows.append({"condition": f"{condition}@{_label(gain, norm)}", "run": run, "LC.gain": gain,
                         "world.normalise": norm, "gated_sources": baseline[run] + shift + noise[run],
                         "exact_order": bool((run + int(gain * 2)) % 3 == 0)})
    return pd.DataFrame(rows)


def test_split_condition_and_points(sweep_runs):
    assert split_condition("curious@LC.gain=0.5,world.normalise=image") == ("curious", "LC.gain=0.5,world.normalise=image")
    assert split_condition("curious") == ("curious", "")
    assert sweep_columns(sweep_runs) == ["LC.gain", "world.normalise"]
    points = sweep_points(sweep_runs)
    assert len(points) == 12 and list(points.columns) == ["condition", "base", "point", "LC.gain", "world.normalise"]
    assert points.iloc[0].tolist() == ["curious@" + _label(0.5, "global"), "curious", _label(0.5, "global"), 0.5, "global"]


def test_per_run_carries_the_swept_columns():
    episodes, modules = [], []
    for gain, run in itertools.product((0.5, 1.0), range(2)):
        condition = f"curious@LC.gain={gain}"
        episodes.append(pd.DataFrame({"condition": condition, "run": run, "LC.gain": gain, "episode": range(3),
                                      "n_frames": 100, "context": [0, 2, 3]}))
        modules.append(pd.DataFrame({"condition": [condition], "run": [run], "LC.gain": [gain], "module": [0],
                                     "source": ["S-A"], "gates": ["C1"]}))
    runs = per_run(results_of(pd.concat(episodes), pd.concat(modules)))
    assert list(runs.columns[:4]) == ["condition", "run", "LC.gain", "n_steps"]
    assert runs["LC.gain"].tolist() == [0.5, 0.5, 1.0, 1.0] and runs["run"].tolist() == [0, 1, 0, 1]
    assert runs["gated_sources"].tolist() == [1, 1, 1, 1]


def test_every_point_against_the_reference_point(sweep_runs):
    reference = {"LC.gain": 1.0, "world.normalise": "global"}
    table = compare_to_point(sweep_runs, reference, ["gated_sources", "exact_order"])
    assert list(table.columns) == ["condition", "point", "LC.gain", "world.normalise", *COMPARE_COLUMNS]
    assert len(table) == 2 * 5 * 2                                  # conditions × other points × metrics
    assert set(table["a"]) == {"curious@" + _label(1.0, "global"), "random_switching@" + _label(1.0, "global")}
    row = table[(table["condition"] == "curious") & (table["point"] == _label(2.0, "image"))
                & (table["metric"] == "gated_sources")].iloc[0]
    assert (row["LC.gain"], row["world.normalise"], row["b"]) == (2.0, "image", "curious@" + _label(2.0, "image"))
    single = compare(sweep_runs, row["a"], row["b"], "gated_sources", adjust=None).iloc[0]
    assert row["p_value"] == single["p_value"] and row["n_pairs"] == RUNS
    assert row["difference"] == pytest.approx(-2.0, abs=0.3)         # reference 1.0 vs gain 2.0
    assert row["p_value"] < 0.001                                    # paired: the baseline cancels
    np.testing.assert_allclose(table["p_adjusted"], multipletests(table["p_value"], method="holm")[1])
    assert (table["p_adjusted"] >= table["p_value"]).all() and (table["n_tests"] == len(table)).all()
    by_label = compare_to_point(sweep_runs, _label(1.0, "global"), ["gated_sources", "exact_order"])
    pd.testing.assert_frame_equal(table, by_label)
    one = compare_to_point(sweep_runs, reference, "gated_sources", conditions=["random_switching"], adjust="bh")
    assert set(one["condition"]) == {"random_switching"} and (one["adjustment"] == "fdr_bh").all()


def test_reference_point_errors(sweep_runs):
    with pytest.raises(ValueError, match="2 points of 'curious' match"):
        compare_to_point(sweep_runs, {"LC.gain": 1.0}, "gated_sources")
    with pytest.raises(ValueError, match="not swept"):
        compare_to_point(sweep_runs, {"LC.rate": 1.0}, "gated_sources")
    with pytest.raises(ValueError, match="no condition has the point"):
        compare_to_point(sweep_runs, "LC.gain=3.0,world.normalise=global", "gated_sources")
    with pytest.raises(ValueError, match="no condition 'lesion'"):
        compare_to_point(sweep_runs, _label(1.0, "global"), "gated_sources", conditions=["lesion"])


def test_every_condition_against_the_reference_at_each_point(sweep_runs):
    table = compare_to_condition(sweep_runs, "random_switching", "gated_sources")
    assert len(table) == 6 and set(table["condition"]) == {"curious"}
    assert table["point"].tolist() == [_label(g, n) for g, n in itertools.product(GAINS, NORMS)]
    assert (table["a"] == "random_switching@" + table["point"]).all()
    assert (table["b"] == "curious@" + table["point"]).all()
    # curious is one unit higher at every point: reference − curious ≈ −1, found on every run pair
    np.testing.assert_allclose(table["difference"], -1.0, atol=0.3)
    assert (table["effect_size"] < -0.9).all() and (table["p_value"] < 0.01).all()
    np.testing.assert_allclose(table["p_adjusted"], multipletests(table["p_value"], method="holm")[1])
    with pytest.raises(ValueError, match="no condition 'lesion'"):
        compare_to_condition(sweep_runs, "lesion")


def test_without_a_sweep_the_point_is_empty(tables):
    runs = per_run(results_of(*tables))
    table = compare_to_condition(runs, "curious", "gated_sources")
    assert table[["condition", "point", "a", "b"]].values.tolist() == [["random_switching", "", "curious",
                                                                          "random_switching"]]
    assert table.iloc[0]["p_value"] == compare(runs, "curious", "random_switching", metric="gated_sources").iloc[0]["p_value"]
