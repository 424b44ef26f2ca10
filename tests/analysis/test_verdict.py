"""The verdict under the order table: "differs?" and "paper within CI?" on hand-made runs with known answers."""

from __future__ import annotations

import math

import pytest
import scipy.stats as sps
from fake_runs import CYCLE, make_run

from neurocur.analysis import Results
from neurocur.analysis.stats.verdict import (
    count_reached,
    differs,
    fewest_runs,
    mean_reached,
    paper_range,
    verdict_notes,
    verdict_table,
)

EXACT = [(10, "S-A", "C1,C2"), (25, "S-B", "C3"), (50, "S-C", "C4")]   # S-A first, exact order, 3 modules
NONE: list = []                                                      # nothing stored


def _folder(write_folder, tmp_path, curious, random, descriptions=True):
    runs = {"curious": [make_run(CYCLE, s, seed=i) for i, s in enumerate(curious)],
            "random_switching": [make_run(CYCLE, s, seed=50 + i) for i, s in enumerate(random)]}
    root = write_folder(tmp_path / "synthetic", runs)
    if descriptions:
        text = (root / "config.toml").read_text()
        head = '[conditions."curious"]\n'
        assert head in text
        text = text.replace(head, head + 'description = "the curious agent"\n')
        (root / "config.toml").write_text(text)
    return Results.load(root)


def test_paper_range_reads_counts_ranges_and_points():
    assert paper_range("18/25") == (0.72, 0.72, 25)
    assert paper_range("2–3") == (2.0, 3.0, None)
    assert paper_range("≈15") == (15.0, 15.0, None)
    assert paper_range("0.81") == (0.81, 0.81, None)


def test_count_reached_is_the_clopper_pearson_interval():
    # 6/8: the exact 95 % interval is [0.349, 0.968]; 25/25 = 1 is outside, 18/25 = 0.72 inside
    low, high = sps.binomtest(6, 8).proportion_ci(0.95, method="exact")
    assert low == pytest.approx(0.3491, abs=1e-3) and high == pytest.approx(0.9685, abs=1e-3)
    assert count_reached(6, 8, 1.0) is False
    assert count_reached(6, 8, 0.72) is True
    assert count_reached(8, 8, 1.0) is True
    # a 90 % interval is narrower: 0.35 is inside the 95 % interval of 6/8 but not the 90 % one
    assert count_reached(6, 8, 0.36, 0.95) is True
    assert count_reached(6, 8, 0.36, 0.90) is False
    assert count_reached(0, 0, 0.5) is None


def test_mean_reached_overlaps_a_range():
    values = [14.0, 15.0, 16.0, 15.0, 14.5, 15.5]
    assert mean_reached(values, 15.0, 15.0) is True
    assert mean_reached(values, 40.0, 40.0) is False
    assert mean_reached(values, 16.0, 20.0) is False     # the mean's interval stays below 16
    assert mean_reached(values, 15.4, 20.0) is True      # overlaps the interval's top
    assert mean_reached([math.nan], 1.0, 2.0) is None


def test_fewest_runs_against_the_holm_floor():
    for n_tests in (1, 4, 8, 20):
        n = fewest_runs(n_tests)
        assert n_tests * 2 / 2 ** n < 0.05 <= n_tests * 2 / 2 ** (n - 1)
    assert fewest_runs(1) == 6          # 2/32 = 0.0625 > 0.05, 2/64 = 0.031


def test_differs_at_alpha():
    assert differs(0.049) is True and differs(0.05) is False and differs(math.nan) is None
    assert differs(0.08, alpha=0.1) is True


def test_ten_to_none_differs_and_reaches_the_paper(write_folder, tmp_path):
    # curious stores S-A, S-B, S-C in that order in all 10 runs; random switching stores nothing:
    # McNemar exact on 10 discordant pairs p = 2/2^10, Holm over the table's 7 tests (8 rows, but Kendall τ
    # has no pair: random switching learns nothing) at most 7 x that
    results = _folder(write_folder, tmp_path, [EXACT] * 10, [NONE] * 10)
    table = verdict_table(results, "curious", "random_switching", n_boot=500)
    test_column = next(c for c in table.columns if c.startswith("curious vs random_switching: p"))
    assert "n = 10 paired runs" in test_column and "Holm over 7 tests" in test_column
    row = table.loc["S-A first"]
    assert (row["paper"], row["curious"], row["random_switching"]) == ("25/25", "10/10", "0/10")
    p, test = row[test_column].split(" ")
    assert test == "(McNemar)" and float(p) == pytest.approx(7 * 2 / 2 ** 10, rel=0.03)
    assert row["differs?"] == "yes" and row["paper within CI?"] == "yes"
    assert table.loc["modules per run", "differs?"] == "yes"        # Wilcoxon: 3 against 0 in every pair
    assert table.loc["modules per run", test_column].endswith("(Wilcoxon)")
    assert table.loc["modules per run", "paper within CI?"] == "yes"  # 3 modules, the paper's 3
    # exact order 10/10: its Clopper–Pearson interval [0.692, 1] holds the paper's 18/25 = 0.72
    assert table.loc["exact S-A→S-B→S-C", "paper within CI?"] == "yes"
    assert table.loc["S-D stored", "differs?"] == "no"              # neither stores S-D: nothing discordant
    assert table.loc["S-D stored", "paper within CI?"] == "yes"


def test_few_runs_do_not_differ_and_miss_the_paper(write_folder, tmp_path):
    # 3 of 4 runs store S-A first, against 2 of 4: one discordant pair, McNemar p = 1;
    # 3/4's interval [0.19, 0.99] misses the paper's 25/25
    curious = [EXACT, EXACT, EXACT, [(10, "S-B", "C3")]]
    random = [EXACT, EXACT, NONE, [(10, "S-B", "C3")]]
    results = _folder(write_folder, tmp_path, curious, random)
    table = verdict_table(results, "curious", "random_switching", n_boot=500)
    row = table.loc["S-A first"]
    assert (row["curious"], row["random_switching"]) == ("3/4", "2/4")
    assert row["differs?"] == "no" and row["paper within CI?"] == "no"
    times = table.loc["S-A learning time (epochs)"]                # not tested: runs without S-A have none
    assert times["differs?"] == "—" and times[next(c for c in table.columns if " vs " in c)] == "—"


def test_verdict_table_without_the_paper_has_no_paper_column(write_folder, tmp_path):
    results = _folder(write_folder, tmp_path, [EXACT] * 3, [NONE] * 3)
    table = verdict_table(results, "curious", "random_switching", with_paper=False, n_boot=200)
    assert "paper" not in table.columns and set(table["paper within CI?"]) == {"—"}


def test_notes_state_the_rules_the_floor_and_the_conditions(write_folder, tmp_path):
    results = _folder(write_folder, tmp_path, [EXACT] * 8, [NONE] * 8)
    lines = verdict_notes(results, "curious", "random_switching", n_tests=8)
    # 2 / 2^8 = 0.0078; x 8 tests = 0.0625 > 0.05; 9 runs: 8 x 2 / 2^9 = 0.031 < 0.05
    assert "p is at least 0.0078, Holm-adjusted at least 0.062: a yes needs 9 or more runs" in lines[0]
    assert "Holm" in lines[0] and "Clopper–Pearson" in lines[1]
    assert "curious: the curious agent" in lines
    assert "random_switching: no description in config.toml" in lines


def test_verdict_text_prints_table_and_notes(write_folder, tmp_path):
    from neurocur.analysis import verdict_text

    results = _folder(write_folder, tmp_path, [EXACT] * 3, [NONE] * 3)
    assert results.conditions == ["curious", "random_switching"]
    text = verdict_text(tmp_path / "synthetic")
    assert text.startswith("verdict: curious against random_switching")
    assert "differs?" in text and "paper within CI?" in text and "curious: the curious agent" in text
