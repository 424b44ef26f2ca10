"""The Goldilocks experiment: its graded world, a short run end to end, and the engagement analysis."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis import engagement_by_learnability, fig_goldilocks, goldilocks_tests, load, world_learnability
from neurocur.analysis.io import source_specs
from neurocur.contexts.gym import GymWorld
from neurocur.contexts.learnability import learnability
from neurocur.contexts.sources import sinusoid_pair
from neurocur.experiments import load_experiment, run_experiment
from neurocur.learn.omega import omega

CONDITIONS = ["learning_progress", "state_progress", "abs_learning_progress", "surprise", "content_novelty",
              "count_novelty", "no_dopamine", "random_switching"]


def test_the_shipped_world_spans_easy_to_unlearnable():
    exp = load_experiment("goldilocks")
    assert list(exp.conditions) == CONDITIONS
    world = exp.conditions["learning_progress"].make_world()
    world.reset(seed=0)
    table = learnability(world, draws=4)
    assert table["source"].tolist() == [f"G{i}" for i in range(1, 9)]
    assert table["level"].tolist() == [1, 2, 3, 4, 5, 6, 7, 7]  # the two redrawn noise sources share the top
    sinusoids = table[~table["redrawn"]]
    for k, value in zip((70, 44, 24, 12, 6, 3), sinusoids["omega"]):
        assert value == pytest.approx(omega(sinusoid_pair(k), 0.05), abs=1e-9)
    assert sinusoids["omega"].iloc[0] == pytest.approx(0.990, abs=5e-4) and sinusoids["omega"].iloc[-1] > 0.99998
    assert np.all(np.diff(sinusoids["omega"]) > 0)
    noise = table[table["redrawn"]].set_index("source")
    assert noise.loc["G7", "omega_draw_min"] > 0.99999  # the isotropic walk: Omega 1 in every draw
    assert noise.loc["G8", "omega_draw_max"] < 0.999  # white noise: each draw alone looks learnable
    assert world.source_spec().learnable == tuple(f"G{i}" for i in range(1, 7))


def test_learnability_needs_frames():
    world = GymWorld(["CartPole-v1"], visit_length=3, frame_shape=(4, 6))
    world.reset(seed=0)
    with pytest.raises(ValueError, match="GymWorld does not expose them"):
        learnability(world)
    world.close()


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("goldilocks")
    exp = load_experiment("goldilocks", runs=2, steps=2000)
    run_experiment(exp, out, jobs=1, conditions=["learning_progress", "random_switching"], progress=False)
    return out


def test_a_short_run_and_its_engagement_table(short_run):
    episodes, _ = load(short_run)
    levels = world_learnability(short_run, draws=3)
    table = engagement_by_learnability(episodes, levels, source_specs(short_run))
    assert len(table) == 2 * 2 * 8  # conditions x runs x contexts, unvisited contexts included
    shares = table.groupby(["condition", "run"])["share"].sum()
    np.testing.assert_allclose(shares, 1.0)
    for (condition, run), rows in table.groupby(["condition", "run"]):
        frames = episodes[(episodes["condition"] == condition) & (episodes["run"] == run)]
        per_context = frames.groupby("context")["n_frames"].sum()
        np.testing.assert_array_equal(rows.set_index("context")["frames"].reindex(per_context.index), per_context)
    assert table.groupby("source")["level"].first().to_dict() == {f"G{i}": min(i, 7) for i in range(1, 9)}


def test_goldilocks_tests_and_figure(short_run):
    episodes, _ = load(short_run)
    table = engagement_by_learnability(episodes, world_learnability(short_run, draws=3), source_specs(short_run))
    tests = goldilocks_tests(table, n_boot=50)
    assert tests[["y", "condition"]].apply(tuple, axis=1).tolist() == [
        (y, c) for y in ("share", "mean_dwell_frames") for c in ("learning_progress", "random_switching")]
    both = tests[["p1", "p2"]].notna().all(axis=1)
    np.testing.assert_array_equal(tests.loc[both, "p_value"], np.maximum(tests.loc[both, "p1"], tests.loc[both, "p2"]))
    assert (tests["p_adjusted"].dropna() >= tests["p_value"].dropna()).all()
    assert set(tests["n_tests"]) <= {0, 1, 2} and set(tests["adjustment"]) == {"holm"}
    fig = fig_goldilocks(table)
    assert len(fig.axes) == 2 and [t.get_text() for t in fig.axes[1].get_xticklabels()][-1] == "G8\nredrawn"


def test_goldilocks_tests_find_a_planted_interior_peak():
    """Engagement that peaks at level 4 of 7 in every run: the two-lines test finds it; a monotone
    rise does not count as a peak."""
    rng = np.random.default_rng(0)
    rows = []
    for run in range(12):
        for level in range(1, 8):
            rows.append({"condition": "peaked", "run": run, "level": level,
                         "share": 0.3 - 0.04 * abs(level - 4) + rng.normal(0, 0.01), "mean_dwell_frames": 1.0})
            rows.append({"condition": "rising", "run": run, "level": level,
                         "share": 0.02 * level + rng.normal(0, 0.01), "mean_dwell_frames": 1.0})
    tests = goldilocks_tests(pd.DataFrame(rows), outcomes=["share"], n_boot=50).set_index("condition")
    assert tests.loc["peaked", "interior_peak"] and tests.loc["peaked", "p_adjusted"] < 0.001
    assert not tests.loc["rising", "interior_peak"] and tests.loc["rising", "p_value"] > 0.5
