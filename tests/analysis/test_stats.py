"""Statistics on hand-made tables whose answers are worked out by hand."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from neuro_tables import results_of

from neurocur.analysis import (
    SYNTHETIC,
    clopper_pearson,
    compare,
    condition_summary,
    learning_time_summary,
    learning_times,
    load,
    order_counts,
    order_table,
    order_tables,
    per_run,
    position_counts,
    summary,
)


def _tag(episodes, modules, condition="curious", run=0):
    return (episodes.assign(condition=condition, run=run),
            modules.assign(condition=condition, run=run))


# --- Clopper–Pearson ------------------------------------------------------------------------

@pytest.mark.parametrize(
    ("k", "n", "low", "high"),
    [
        (18, 25, 0.50612, 0.87930),   # exact interval for 18/25
        (7, 25, 0.12072, 0.49388),
        (0, 25, 0.0, 0.13719),        # upper = 1 - 0.025**(1/25)
        (25, 25, 0.86281, 1.0),
    ],
)
def test_clopper_pearson_known_values(k, n, low, high):
    lo, hi = clopper_pearson(k, n)
    assert lo == pytest.approx(low, abs=5e-5)
    assert hi == pytest.approx(high, abs=5e-5)


def test_clopper_pearson_edges_are_closed_form():
    assert clopper_pearson(0, 25)[1] == pytest.approx(1 - 0.025 ** (1 / 25), rel=1e-9)
    assert clopper_pearson(25, 25)[0] == pytest.approx(0.025 ** (1 / 25), rel=1e-9)
    assert all(math.isnan(v) for v in clopper_pearson(0, 0))


def test_clopper_pearson_rejects_bad_counts():
    with pytest.raises(ValueError, match="0 <= k <= n"):
        clopper_pearson(5, 3)


# --- load ------------------------------------------------------------------------------------

def test_load_concatenates_runs(tables):
    episodes, modules = tables
    assert sorted(episodes.groupby("condition")["run"].nunique().items()) == [
        ("curious", 4), ("random_switching", 3)]
    assert len(episodes) == 7 * 60
    assert list(episodes.columns[:2]) == ["condition", "run"]
    assert len(modules) == 3 + 3 + 4 + 2 + 0 + 1 + 2
    assert modules["gates"].map(type).eq(str).all()


def test_load_rejects_a_folder_that_is_not_results(tmp_path):
    with pytest.raises(ValueError, match="not a results folder"):
        load(tmp_path)
    (tmp_path / "runs").mkdir()
    with pytest.raises(ValueError, match="no run folder"):
        load(tmp_path)
    (tmp_path / "runs" / "curious" / "run-000").mkdir(parents=True)
    with pytest.raises(ValueError, match="lacks episodes.parquet"):
        load(tmp_path)
    with pytest.raises(ValueError, match="does not exist"):
        load(tmp_path / "missing")


# --- per-run metrics and order counts -------------------------------------------------------

def test_statistics_name_the_missing_column(tables):
    episodes, modules = tables
    with pytest.raises(ValueError, match=r"per_run \(modules table\) needs the column\(s\) 'gates'"):
        per_run(results_of(episodes, modules.drop(columns="gates")))
    with pytest.raises(ValueError, match=r"order_counts \(episodes table\) needs the column\(s\) 'n_frames' \(from sensory\)"):
        order_counts(results_of(episodes.drop(columns="n_frames"), modules))
    with pytest.raises(ValueError, match=r"learning_times \(episodes table\) needs the column\(s\) 'context'"):
        learning_times(results_of(episodes.drop(columns="context"), modules))
    with pytest.raises(ValueError, match=r"summary \(modules table\) needs the column\(s\) 'episode' \(from scheduler\)"):
        summary(results_of(episodes, modules.drop(columns="episode")))


def test_per_run_metrics(tables):
    runs = per_run(results_of(*tables)).set_index(["condition", "run"])
    cur = runs.loc["curious"]
    assert cur["order"].tolist() == ["S-A,S-B,S-C", "S-A,S-C,S-B", "S-A,S-B,S-C,S-D", "S-A,S-B"]
    assert cur["exact_order"].tolist() == [True, False, True, False]
    assert cur["unlearnable_stored"].tolist() == [False, False, True, False]
    assert cur["gated_sources"].tolist() == [3, 3, 3, 1]
    assert cur["n_modules"].tolist() == [3, 3, 4, 2]
    np.testing.assert_allclose(cur["kendall_tau"], [1.0, 1 / 3, 1.0, 1.0])
    rnd = runs.loc["random_switching"]
    assert rnd["n_modules"].tolist() == [0, 1, 2]
    assert rnd["gated_sources"].tolist() == [0, 1, 0]
    assert rnd["first"].tolist() == ["", "S-A", "S-B"]
    assert math.isnan(rnd["kendall_tau"].iloc[0]) and math.isnan(rnd["kendall_tau"].iloc[1])
    assert rnd["kendall_tau"].iloc[2] == pytest.approx(-1.0)
    assert (runs["n_steps"] == 6000).all()


def test_order_counts(tables):
    counts = order_counts(results_of(*tables)).set_index(["condition", "outcome"])
    expected = {
        ("curious", "S-A first"): (4, 4), ("curious", "S-B second"): (3, 4),
        ("curious", "S-C third"): (2, 4), ("curious", "exact S-A→S-B→S-C"): (2, 4),
        ("curious", "S-D stored"): (1, 4),
        ("random_switching", "S-A first"): (1, 3), ("random_switching", "S-B second"): (0, 3),
        ("random_switching", "exact S-A→S-B→S-C"): (0, 3),
    }
    for key, (k, n) in expected.items():
        assert (counts.loc[key, "k"], counts.loc[key, "n"]) == (k, n)
        assert (counts.loc[key, "ci_low"], counts.loc[key, "ci_high"]) == pytest.approx(clopper_pearson(k, n))
    assert len(counts) == 2 * 5


def test_position_counts(tables):
    counts = position_counts(results_of(*tables))
    cur = counts[(counts["condition"] == "curious")].set_index(["position", "source"])["k"]
    assert cur[(1, "S-A")] == 4 and cur[(2, "S-B")] == 3 and cur[(2, "S-C")] == 1
    assert cur[(3, "S-C")] == 2 and cur[(3, "S-B")] == 1 and cur[(3, "none")] == 1
    assert counts.groupby(["condition", "position"])["k"].sum().tolist() == [4, 4, 4, 3, 3, 3]


def test_condition_summary(tables):
    summ = condition_summary(results_of(*tables)).set_index(["condition", "metric"])
    assert summ.loc[("curious", "n_modules"), "mean"] == pytest.approx(3.0)
    assert summ.loc[("curious", "n_modules"), "sd"] == pytest.approx(np.sqrt(2 / 3))
    assert summ.loc[("curious", "gated_sources"), "mean"] == pytest.approx(2.5)
    assert summ.loc[("curious", "kendall_tau"), "mean"] == pytest.approx((3 + 1 / 3) / 4)
    assert summ.loc[("random_switching", "kendall_tau"), "n"] == 1


@pytest.mark.parametrize(("k_true", "expected"), [([0, 1, 2], 1.0), ([2, 1, 0], -1.0), ([1, 0, 2], 1 / 3)])
def test_kendall_tau_against_omega_order(k_true, expected):
    order = [SYNTHETIC.learnable[i] for i in k_true]
    episodes, modules = _tag(*_hand_run(order))
    tau = per_run(results_of(episodes, modules))["kendall_tau"].iloc[0]
    assert tau == pytest.approx(expected)


def _hand_run(order):
    contexts = [0, 2, 3, 4] * 3
    episodes = pd.DataFrame({"episode": range(12), "step": np.arange(12) * 100, "context": contexts,
                             "n_frames": 100})
    modules = pd.DataFrame({"module": range(len(order)), "episode": [3 * i + 2 for i in range(len(order))],
                            "source": order, "gates": ""})
    return episodes, modules


# --- learning time ---------------------------------------------------------------------------

def _learning_time_tables():
    episodes = pd.DataFrame({
        "episode": range(10),
        "context": [0, 2, 0, 1, 2, 3, 2, 4, 3, 3],
        "n_frames": [100, 150, 100, 200, 50, 100, 100, 100, 300, 100],
    })
    episodes["step"] = np.concatenate([[0], np.cumsum(episodes["n_frames"])[:-1]])
    modules = pd.DataFrame({"module": [0, 1, 2, 3], "episode": [3, 6, 8, 9],
                            "source": ["S-A", "S-B", "S-C", "S-C"], "gates": ["C1", "C3", "C4", ""]})
    return _tag(episodes, modules)


def test_learning_time_from_previous_module():
    # S-A: episodes 0..3 in C1/C2 -> 100+100+200; S-B: 4..6 in C3 -> 50+100; S-C: 7..8 in C4 -> 300;
    # the second S-C module: episode 9 only (the previous storage episode 8 is excluded) -> 100
    times = learning_times(results_of(*_learning_time_tables()))
    np.testing.assert_allclose(times["epochs"], [0.4, 0.15, 0.3, 0.1])
    assert times["first_of_source"].tolist() == [True, True, True, False] and times["learnable"].all()


def test_learning_time_from_start():
    # S-B: episodes 1, 4, 6 -> 150+50+100; S-C: 5, 8 -> 100+300, then 5, 8, 9 -> 100+300+100
    times = learning_times(results_of(*_learning_time_tables()), since="start")
    np.testing.assert_allclose(times["epochs"], [0.4, 0.3, 0.4, 0.5])


def test_learning_time_summary(tables):
    summ = learning_time_summary(results_of(*tables)).set_index(["condition", "source"])
    times = learning_times(results_of(*tables))
    # curious S-A: every run stores S-A at episode 10; episodes 0..10 in C1/C2 of the cycle
    cycle_sa = sum(1 for e in range(11) if [c for c in range(5) for _ in range(3)][e % 15] in (0, 1))
    assert summ.loc[("curious", "S-A"), "mean"] == pytest.approx(cycle_sa * 100 / 1000)
    assert summ.loc[("curious", "S-A"), "n"] == 4
    assert summ.loc[("random_switching", "S-C"), "n"] == 0
    duplicated = times[(times["condition"] == "curious") & (times["run"] == 2)]
    assert duplicated["source"].tolist() == ["S-A", "S-B", "S-C", "S-D"]
    assert not duplicated["learnable"].iloc[-1]


# --- comparisons -----------------------------------------------------------------------------

def test_compare_fully_separated_samples():
    runs = pd.DataFrame({"condition": ["curious"] * 5 + ["random_switching"] * 5,
                         "gated_sources": [3, 3, 2, 3, 3, 0, 1, 0, 0, 1]})
    row = compare(runs, "curious", "random_switching", metric="gated_sources", paired=False).iloc[0]
    assert row["method"] == "mann_whitney_u"
    assert row["effect_size"] == pytest.approx(1.0)
    assert row["statistic"] == pytest.approx(25.0)
    assert row["p_value"] < 0.02
    reverse = compare(runs, a="random_switching", b="curious", metric="gated_sources", paired=False).iloc[0]
    assert reverse["effect_size"] == pytest.approx(-1.0)
    assert reverse["p_value"] == pytest.approx(row["p_value"])


def test_compare_binary_uses_fisher():
    runs = pd.DataFrame({"condition": ["curious"] * 10 + ["random_switching"] * 10,
                         "exact_order": [True] * 8 + [False] * 2 + [True] * 1 + [False] * 9})
    row = compare(runs, "curious", "random_switching", metric="exact_order", paired=False).iloc[0]
    assert row["method"] == "fisher_exact"
    assert row["effect_size"] == pytest.approx((8 * 9) / (2 * 1))
    # two-sided Fisher p for [[8, 2], [1, 9]] = 0.00547 (hypergeometric tail sum)
    assert row["p_value"] == pytest.approx(0.005477, abs=2e-5)
    assert (row["value_a"], row["value_b"]) == (0.8, 0.1)


def test_compare_on_tables(tables):
    runs = per_run(results_of(*tables))
    unpaired = compare(runs, "curious", "random_switching", paired=False).set_index("metric")
    assert unpaired.loc["gated_sources", "effect_size"] == pytest.approx(2 * 11.5 / 12 - 1)
    assert unpaired.loc["exact_order", "method"] == "fisher_exact"
    result = compare(runs, "curious", "random_switching").set_index("metric")
    assert result.loc["exact_order", "method"] == "mcnemar_exact"
    assert result.loc["gated_sources", "method"] == "wilcoxon"
    assert result.loc["kendall_tau", "n_b"] == 1 and result.loc["kendall_tau", "n_pairs"] == 1
    with pytest.raises(ValueError, match="not in the results"):
        compare(runs, "curious", "lesion_lc")
    with pytest.raises(ValueError, match="unknown metric"):
        compare(runs, "curious", "random_switching", metric="happiness")


# --- order table and summary -----------------------------------------------------------------

def test_order_table(tables):
    table = order_table(results_of(*tables))
    assert list(table.columns) == ["paper", "paper (random)", "curious", "random_switching"]
    assert table.loc["S-A first", "paper"] == "25/25"
    assert table.loc["S-A first", "curious"] == "4/4"
    assert table.loc["S-B second", "curious"] == "3/4"
    assert table.loc["S-D stored", "random_switching"] == "0/3"
    assert table.loc["modules per run", "curious"] == "3.00 ± 0.82"
    assert table.loc["learnable sources gated", "curious"] == "2.50 ± 1.00"
    assert table.loc["S-C learning time (epochs)", "random_switching"] == "—"


GATED_ROW = "learnable sources gated vs curious: Wilcoxon signed-rank p (paired; Holm, 2 tests)"
EXACT_ROW = "exact S-A→S-B→S-C vs curious: McNemar exact p (paired; Holm, 2 tests)"


def test_order_table_names_the_test_of_every_p_value(tables):
    assert order_table(results_of(*tables)).index[-1] == "S-C learning time (epochs)"      # no reference, no tests
    table = order_table(results_of(*tables), reference="curious")
    assert list(table.index[-2:]) == [EXACT_ROW, GATED_ROW]
    # 3 pairs (run 3 has no random twin); exact order 2 discordant, p 0.5; gated 3 of 3 up, p 0.25;
    # Holm over the two: 2 × 0.25 = 0.5, then max(0.5, 0.5)
    assert table.loc[GATED_ROW, "random_switching"] == "0.5 (n=3)"
    assert table.loc[EXACT_ROW, "random_switching"] == "0.5 (2 of 3 discordant)"
    assert (table.loc[[EXACT_ROW, GATED_ROW], ["paper", "paper (random)", "curious"]] == "—").all().all()
    bh = order_table(results_of(*tables), reference="curious", adjust="bh")
    assert bh.index[-1] == GATED_ROW.replace("Holm", "Benjamini–Hochberg")


def test_order_tables_of_a_folder_test_against_its_first_condition(results_dir):
    table = order_tables(results_dir)
    assert list(table.columns) == ["paper", "paper (random)", "curious", "random_switching"]
    assert table.loc[GATED_ROW, "random_switching"] == "0.5 (n=3)"
    assert order_tables(results_dir, tests=False).index[-1] == "S-C learning time (epochs)"
    other = order_tables(results_dir, reference="random_switching")
    assert other.loc[GATED_ROW.replace("vs curious", "vs random_switching"), "curious"] == "0.5 (n=3)"
    assert order_tables(results_dir, conditions=["curious"]).index[-1] == "S-C learning time (epochs)"
    episodes, modules = load(results_dir)
    pd.testing.assert_frame_equal(order_tables(results_dir, tables=(episodes, modules)), table)
    fewer = order_tables(results_dir, tables=(episodes, modules[modules["module"] > 0]), tests=False)
    assert fewer.loc["modules per run", "curious"] != table.loc["modules per run", "curious"]  # the tables given are read


def test_summary_is_json(tables):
    result = summary(results_of(*tables))
    text = json.dumps(result, allow_nan=False)
    back = json.loads(text)
    assert back["n_runs"] == {"curious": 4, "random_switching": 3}
    assert {r["metric"] for r in back["comparisons"]} >= {"gated_sources", "exact_order"}
    assert any(r["outcome"] == "S-A first" and r["k"] == 4 for r in back["order_counts"])


def test_summary_records_the_tests_and_the_adjustment(tables):
    back = json.loads(json.dumps(summary(results_of(*tables)), allow_nan=False))
    stats = back["statistics"]
    assert stats["paired"] is True and stats["pairing"] == "run" and stats["reference"] == "curious"
    assert stats["tests"] == {"mcnemar_exact": {"name": "McNemar exact", "reference": "McNemar 1947"},
                              "wilcoxon": {"name": "Wilcoxon signed-rank", "reference": "Wilcoxon 1945"}}
    assert stats["adjustment"] == {"method": "holm", "name": "Holm", "reference": "Holm 1979", "n_tests": 9}
    assert stats["bootstrap"]["seed"] == 2013 and stats["bootstrap"]["n_boot"] == 2000
    gated = next(r for r in back["comparisons"] if r["metric"] == "gated_sources")
    assert gated["test"].startswith("Wilcoxon signed-rank (paired by run, n=3 pairs")
    assert gated["p_value"] == pytest.approx(0.25) and gated["p_adjusted"] >= gated["p_value"]
    assert gated["adjustment"] == "holm" and gated["n_tests"] == 9
    unpaired = summary(results_of(*tables), paired=False, adjust="bh")["statistics"]
    assert set(unpaired["tests"]) == {"mann_whitney_u", "fisher_exact"} and unpaired["adjustment"]["method"] == "fdr_bh"
    assert summary(results_of(*tables), reference="lesion")["comparisons"] == []
