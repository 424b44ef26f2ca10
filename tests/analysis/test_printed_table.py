"""The order table as `neurocur run` prints it: paper columns for the paper's experiments only,
printed within 100 columns."""

from __future__ import annotations

import pytest
from fake_runs import CYCLE, make_run

from neurocur.analysis import narrow, order_tables


def _folder(tmp_path, write_folder, name):
    runs = {"curious": [make_run(CYCLE, [(5, "S-A", "C1")], seed=i) for i in range(2)],
            "random_switching": [make_run(CYCLE, [], seed=10 + i) for i in range(2)]}
    folder = write_folder(tmp_path / (name or "unnamed"), runs)
    if name is not None:
        config = folder / "config.toml"
        config.write_text(f'name = "{name}"\n' + config.read_text())
    return folder


@pytest.mark.parametrize(("name", "paper"), [("synthetic", True), ("reproduction", True), ("lesion", False),
                                             ("my_world", False)])
def test_the_paper_columns_are_only_beside_the_papers_experiments(tmp_path, write_folder, name, paper):
    table = order_tables(_folder(tmp_path, write_folder, name))
    assert ("paper" in table.columns) == paper and ("paper (random)" in table.columns) == paper
    assert list(table.columns[-2:]) == ["curious", "random_switching"]


def test_the_printed_table_fits_100_columns_and_says_every_cell(results_dir):
    table = order_tables(results_dir)
    assert max(len(line) for line in table.to_string().splitlines()) > 100  # the wide form does not fit
    text = narrow(table)
    assert max(len(line) for line in text.splitlines()) <= 100
    for label, row in table.iterrows():
        assert label[:60] in text
        for column, value in row.items():
            if value != "—":
                assert f"{column}: {value}" in text
    assert "curious: 4/4" in text.split("S-A first")[1].splitlines()[1]
