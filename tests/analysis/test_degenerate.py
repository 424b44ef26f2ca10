"""Degenerate conditions: one whose runs repeat another's exactly is reported and left out of the families."""

from __future__ import annotations

import json

from neurocur.analysis import Results, degenerate_conditions, order_table, order_tables, summary

NOTE = "left out of the tests: its runs repeat another condition's, run for run"


def _runs(tables, condition):
    episodes, modules = tables
    return [(e.drop(columns=["condition", "run"]),
             modules[(modules["condition"] == condition) & (modules["run"] == run)].drop(columns=["condition", "run"]))
            for run, e in episodes[episodes["condition"] == condition].groupby("run")]


def _folder(tables, write_folder, path, order=("curious", "td", "random_switching")):
    """The hand-made folder plus ``td``, a copy of random switching's runs but for its DA (a TD VTA
    without extrinsic reward: DA 0 throughout, the decisions of random switching)."""
    runs = {"curious": _runs(tables, "curious"), "random_switching": _runs(tables, "random_switching")}
    runs["td"] = [(e.assign(da=0.0), m) for e, m in runs["random_switching"]]
    return write_folder(path, {name: runs[name] for name in order}, alphas={})


def test_a_condition_repeating_another_is_found_whatever_its_place(tables, write_folder, tmp_path):
    results = Results.load(_folder(tables, write_folder, tmp_path / "a"))
    assert degenerate_conditions(results) == {"td": "random_switching"}  # the declared control is kept
    assert degenerate_conditions(results.select(["curious", "random_switching"])) == {}
    flipped = Results.load(_folder(tables, write_folder, tmp_path / "b", order=("td", "curious", "random_switching")))
    assert degenerate_conditions(flipped) == {"random_switching": "td"}  # td is now the reference
    episodes = results.episodes.copy()
    one = (episodes["condition"] == "td") & (episodes["run"] == 0) & (episodes["episode"] == 5)
    episodes.loc[one, "action"] = episodes.loc[one, "action"].map({"engage": "disengage", "disengage": "engage"})
    assert degenerate_conditions(Results(episodes, results.modules, results.specs, results.config)) == {}


def test_the_printed_table_leaves_it_out_of_the_families_with_a_note(tables, write_folder, tmp_path):
    folder = _folder(tables, write_folder, tmp_path / "a")
    table = order_tables(folder)
    tests = [label for label in table.index if " vs curious: " in label]
    assert tests and all(table.loc[label, "td"] == "—" for label in tests)
    assert all(table.loc[label, "random_switching"] != "—" for label in tests)
    assert all("(paired; Holm, 4 tests)" in label or "(paired; Holm, 2 tests)" in label for label in tests)
    assert table.loc[NOTE].tolist()[-3:] == ["—", "= random_switching", "—"]  # curious, td, random_switching
    kept = order_table(Results.load(folder), reference="curious", exclude_degenerate=False)
    assert NOTE not in kept.index and any("(paired; Holm, 8 tests)" in label for label in kept.index)


def test_the_summary_reports_it_and_leaves_it_out_of_the_comparisons(tables, write_folder, tmp_path):
    result = json.loads(json.dumps(summary(Results.load(_folder(tables, write_folder, tmp_path / "a"))),
                                   allow_nan=False))
    assert result["statistics"]["degenerate"] == {"td": "random_switching"}
    assert {row["b"] for row in result["comparisons"]} == {"random_switching"}
    assert {row["b"] for row in result["efficiency"]["comparisons"]} == {"random_switching"}
    assert result["statistics"]["adjustment"]["n_tests"] == 9  # one condition's nine metrics
    assert "td" in result["n_runs"]                            # still reported
