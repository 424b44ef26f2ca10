"""The reproduction study's table and the paper's numbers, on the hand-made results folders."""

from __future__ import annotations

import runpy
from pathlib import Path

from neuro_tables import results_of

from neurocur.analysis import Results, compare, order_table, paper, per_run
from neurocur.analysis.stats.reproduction import COLUMNS, SHARED_CONTROLS, markdown, study_table

BENCHMARK = Path(__file__).resolve().parents[2] / "benchmarks" / "reproduce_synthetic.py"


def test_every_paper_number_is_a_row_of_the_order_table(tables):
    table = order_table(results_of(*tables))
    for numbers, column in ((paper.SYNTHETIC_CURIOUS, "paper"), (paper.SYNTHETIC_RANDOM, "paper (random)")):
        for label, reported in numbers.items():
            assert table.loc[label, column] == reported.cell()
            assert reported.section.startswith("4.")
    assert table.loc["exact S-A→S-B→S-C", "paper"] == "18/25 (implied)"
    assert (table.loc[[r for r in table.index if r not in paper.SYNTHETIC_RANDOM], "paper (random)"] == "—").all()


def test_study_table_on_the_small_results_folder(results_dir):
    table = study_table(results_dir)
    assert list(table.index) == ["paper", "curious", "random_switching"]
    assert list(table.columns) == COLUMNS
    assert table.loc["paper"].tolist() == [paper.SYNTHETIC_CURIOUS[c].value for c in COLUMNS[:-3]] + ["—"] * 3
    assert table.loc["curious", "S-A first"] == "4/4"
    assert table.loc["curious", "modules per run"] == "3.00 ± 0.82"
    assert table.loc["random_switching", "S-B second"] == "0/3"
    # neither condition has a random-switching twin ("curious_random") here
    assert (table[COLUMNS[-3:]] == "—").all().all()


def test_study_table_compares_each_condition_with_its_twin(study_dir):
    assert SHARED_CONTROLS["alpha_005"] == "default_random"
    assert COLUMNS[-3:] == ["gated vs random: Wilcoxon signed-rank p (paired by run)", "Holm-adjusted p",
                            "effect (matched-pairs rank-biserial)"]
    table = study_table(study_dir)
    assert list(table.index) == ["paper", "alpha_005", "default", "default_random"]
    expected = compare(per_run(Results.load(study_dir)), "default", "default_random", metric="gated_sources").iloc[0]
    assert expected.method == "wilcoxon" and expected.n_pairs == 3
    for name in ("default", "alpha_005"):
        # three pairs, all up: p = 2/2**3; Holm over the table's two comparisons: 2 × 0.25
        assert table.loc[name, COLUMNS[-3]] == f"{expected.p_value:.2g}" == "0.25"
        assert table.loc[name, COLUMNS[-2]] == "0.5"
        assert table.loc[name, COLUMNS[-1]] == f"{expected.effect_size:+.2f}" == "+1.00"
    assert (table.loc["default_random", COLUMNS[-3:]] == "—").all()


def test_markdown_and_the_benchmark_script(study_dir, capsys):
    table = study_table(study_dir)
    text = markdown(table)
    lines = text.splitlines()
    assert lines[0] == "| " + " | ".join(["condition", *COLUMNS]) + " |"
    assert len(lines) == 2 + len(table) and lines[2].startswith("| paper | 25/25 |")
    runpy.run_path(str(BENCHMARK), run_name="benchmark")["main"]([str(study_dir), "--markdown"])
    assert capsys.readouterr().out == text + "\n"
