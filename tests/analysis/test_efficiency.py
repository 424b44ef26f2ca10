"""Frames to learn all learnable sources, frames in the unlearnable contexts, modules per 10⁵ frames,
and the paired comparison, on the hand-made runs of conftest.py (known answers)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from neuro_tables import episodes_of, modules_of, results_of, runs_of

from neurocur.analysis import (
    Results,
    compare_efficiency,
    efficiency_per_run,
    efficiency_summary,
    order_table,
    order_tables,
    summary,
)
from neurocur.contexts.base import SourceSpec

CYCLE = [c for c in range(5) for _ in range(3)] * 4   # conftest.py's context sequence


def test_efficiency_per_run(tables):
    table = efficiency_per_run(results_of(*tables)).set_index(["condition", "run"])
    curious = table.loc["curious"]
    # 60 episodes of 100 frames; the module completing S-A, S-B, S-C is stored at episode 50, 50, 40
    assert curious["learned_all"].tolist() == [True, True, True, False]
    assert curious["learned_all_episode"].tolist()[:3] == [50, 50, 40]
    assert curious["frames_to_learn_all"].tolist()[:3] == [5100, 5100, 4100]
    assert math.isnan(curious.loc[3, "frames_to_learn_all"])
    assert curious["frames_to_learn_all_censored"].tolist() == [5100, 5100, 4100, 6000]
    assert curious["n_learned"].tolist() == [3, 3, 3, 2]
    # CYCLE visits C5 (S-D) in 3 of every 15 episodes
    assert (table["frames_unlearnable"] == 1200).all() and (table["share_unlearnable"] == 0.2).all()
    assert curious["modules_per_1e5"].tolist() == pytest.approx([3e5 / 6000, 3e5 / 6000, 4e5 / 6000, 2e5 / 6000])
    assert table.loc[("random_switching", 0), "modules_per_1e5"] == 0.0
    assert not table.loc["random_switching", "learned_all"].any()


def test_frames_to_learn_all_count_every_frame_up_to_the_storing_episode():
    frames = np.where(np.arange(60) % 2 == 0, 100, 250)              # 100, 250, 100, 250, ...
    row = efficiency_per_run(results_of(episodes_of(CYCLE, frames), modules_of([(3, "S-A"), (7, "S-C"), (4, "S-B")]))).iloc[0]
    assert row["learned_all_episode"] == 7
    assert row["frames_to_learn_all"] == frames[:8].sum() == 4 * 100 + 4 * 250


def test_censoring_uses_one_horizon_so_censored_twins_tie():
    spec = SourceSpec(("C1",), ("S-A",), ("S-A",))
    episodes, modules = runs_of(
        (episodes_of([0] * n, condition=condition, run=run),
         modules_of([(20 + 10 * run, "S-A")] if condition == "a" else [], condition=condition, run=run))
        for condition, n in (("a", 61), ("b", 60)) for run in range(3))      # a's runs end a visit later
    table = efficiency_per_run(results_of(episodes, modules, spec))
    assert table.loc[table["condition"] == "a", "frames_to_learn_all"].tolist() == [2100, 3100, 4100]
    assert table.loc[table["condition"] == "b", "frames_to_learn_all_censored"].tolist() == [6000] * 3
    late = efficiency_per_run(results_of(episodes, modules.assign(episode=60), spec))             # learned after the horizon
    assert late.loc[late["condition"] == "a", "frames_to_learn_all"].tolist() == [6100] * 3
    assert late.loc[late["condition"] == "a", "frames_to_learn_all_censored"].tolist() == [6000] * 3
    assert compare_efficiency(late, "a", "b").set_index("metric").loc["frames_to_learn_all_censored",
                                                                      "n_nonzero"] == 0


def test_compare_efficiency_is_paired_by_run(tables):
    result = compare_efficiency(efficiency_per_run(results_of(*tables)), "curious", "random_switching").set_index("metric")
    assert list(result.index) == ["frames_to_learn_all_censored", "learned_all", "frames_unlearnable",
                                  "modules_per_1e5"]
    frames = result.loc["frames_to_learn_all_censored"]
    # pairs 0-2 (run 3 has no random twin): 5100, 5100, 4100 against 6000 censored; all lower, exact p = 2/8
    assert frames["n_pairs"] == 3 and frames["p_value"] == pytest.approx(0.25)
    assert frames["difference"] == pytest.approx((5100 + 5100 + 4100) / 3 - 6000)
    assert frames["effect_size"] == -1.0
    learned = result.loc["learned_all"]
    assert learned["method"] == "mcnemar_exact" and learned["n_nonzero"] == 3 and learned["p_value"] == pytest.approx(0.25)
    assert result.loc["frames_unlearnable", "p_value"] == 1.0                # same visits: all differences zero
    assert (result["adjustment"] == "holm").all() and (result["n_tests"] == 4).all()


def test_eight_pairs_that_all_learn_sooner_give_the_exact_wilcoxon_p():
    spec = SourceSpec(("C1", "C2"), ("S-A", "S-D"), ("S-A",))
    tables = runs_of((episodes_of([0, 1] * 30, condition=condition, run=run),
                      modules_of(stored, condition=condition, run=run))
                     for run in range(8)
                     for condition, stored in (("curious", [(5 + run, "S-A")]), ("random_switching", [])))
    result = compare_efficiency(efficiency_per_run(results_of(*tables, spec)), "curious", "random_switching").set_index("metric")
    assert result.loc["frames_to_learn_all_censored", "p_value"] == pytest.approx(2 / 2**8)
    assert result.loc["learned_all", "p_value"] == pytest.approx(2 / 2**8)       # 8 of 8 discordant one way
    low, high = result.loc["frames_to_learn_all_censored", ["ci_diff_low", "ci_diff_high"]]
    assert low <= result.loc["frames_to_learn_all_censored", "difference"] <= high < 0


def test_efficiency_summary(tables):
    table = efficiency_summary(efficiency_per_run(results_of(*tables))).set_index(["condition", "metric"])
    learned = table.loc[("curious", "learned_all")]
    assert learned["n"] == 4 and learned["mean"] == 0.75
    assert (learned["ci_low"], learned["ci_high"]) == pytest.approx((0.194, 0.994), abs=1e-3)   # Clopper–Pearson 3/4
    did = table.loc[("curious", "frames_to_learn_all")]
    assert did["n"] == 3 and did["mean"] == pytest.approx(14300 / 3) and did["median"] == 5100
    restricted = table.loc[("curious", "frames_to_learn_all_censored")]
    assert restricted["n"] == 4 and restricted["mean"] == pytest.approx((14300 + 6000) / 4)
    assert restricted["ci_low"] <= restricted["mean"] <= restricted["ci_high"]
    assert table.loc[("random_switching", "frames_to_learn_all"), "n"] == 0
    assert math.isnan(table.loc[("random_switching", "frames_to_learn_all"), "mean"])


def test_bad_input_is_named(tables):
    episodes, modules = tables
    with pytest.raises(ValueError, match="'source'"):
        efficiency_per_run(results_of(episodes, modules.drop(columns="source")))
    with pytest.raises(ValueError, match="compare_efficiency needs the column\\(s\\) 'learned_all'"):
        compare_efficiency(efficiency_per_run(results_of(*tables)).drop(columns="learned_all"), "curious", "random_switching")
    with pytest.raises(ValueError, match="efficiency_summary needs the column\\(s\\) 'learned_all'"):
        efficiency_summary(efficiency_per_run(results_of(*tables)).drop(columns="learned_all"))


FRAMES_ROW = "frames to learn all (censored at 6.0k frames, the shortest run) vs curious: Wilcoxon signed-rank p (paired; Holm, 4 tests)"


def test_the_order_table_reports_the_efficiency(tables, results_dir):
    table = order_table(results_of(*tables), reference="curious")
    assert table.loc["all learnable sources learned", "curious"] == "3/4"
    assert table.loc["frames to learn all (runs that did): median (range)", "curious"] == "5.1k (4.1k–5.1k; n=3)"
    assert table.loc["frames to learn all (runs that did): median (range)", "random_switching"] == "—"
    assert table.loc["frames in unlearnable contexts (S-D): mean ± sd", "random_switching"] == "1.2k ± 0.0k"
    # raw p 0.25 (frames), 0.25 (learned all), 1 (S-D), 0.25 (modules); Holm over the four: all 1
    assert table.loc[FRAMES_ROW, "random_switching"] == "1 (n=3)"
    assert table.index[-1].startswith("learnable sources gated vs curious")     # the order family comes last
    assert order_tables(results_dir).loc[FRAMES_ROW, "random_switching"] == "1 (n=3)"


def test_the_summary_reports_the_efficiency(tables):
    result = json.loads(json.dumps(summary(results_of(*tables)), allow_nan=False))["efficiency"]
    restricted = next(r for r in result["summary"]
                      if r["condition"] == "curious" and r["metric"] == "frames_to_learn_all_censored")
    assert restricted["mean"] == pytest.approx((14300 + 6000) / 4)
    frames = next(r for r in result["comparisons"] if r["metric"] == "frames_to_learn_all_censored")
    assert frames["p_value"] == pytest.approx(0.25) and frames["n_tests"] == 4 and frames["b"] == "random_switching"


def _uneven_folder(write_folder, path):
    """Three runs per condition: ``a`` learns S-A, S-B and S-C by episode 20, 30, 40 of its runs, which
    end at 6000 frames; ``b`` learns nothing and its runs end one visit later, at 6100 frames."""
    runs = {}
    for condition, n in (("a", 60), ("b", 61)):
        runs[condition] = []
        for run in range(3):
            episodes = episodes_of(CYCLE[:n] if n <= len(CYCLE) else CYCLE + CYCLE[:n - len(CYCLE)],
                                   familiar=False, module_learned=False, n_modules=0, error=1.0, da=0.0)
            stored = [(10 + 10 * run, "S-A"), (15 + 10 * run, "S-B"), (20 + 10 * run, "S-C")] if condition == "a" else []
            modules = modules_of(stored).assign(gates="")
            runs[condition].append((episodes.drop(columns=["condition", "run"]),
                                    modules.drop(columns=["condition", "run"])))
    return write_folder(path, runs, alphas={}, control="b")


def test_the_printed_table_censors_every_condition_at_one_cut_off(write_folder, tmp_path):
    """The cells of each condition and the test between them use the same cut-off, the shortest run
    of the conditions compared (6000 frames), which the rows name."""
    folder = _uneven_folder(write_folder, tmp_path / "uneven")
    table = order_tables(folder)
    row = "frames to learn all (censored at 6.0k frames, the shortest run): mean ± sd"
    assert table.loc[row, "b"] == "6.0k ± 0.0k"           # b's own runs are 6.1k long: censored at a's 6.0k
    assert table.loc[row, "a"] == "3.1k ± 1.0k"
    tests = [label for label in table.index if label.startswith("frames to learn all (censored at 6.0k frames")]
    assert len(tests) == 2                                    # the cells and the test name the same cut-off
    efficiency = efficiency_per_run(Results.load(folder))
    assert set(efficiency["horizon"]) == {6000.0}
    with pytest.raises(ValueError, match="horizon 6100 is past the shortest run"):
        efficiency_per_run(Results.load(folder), horizon=6100)
