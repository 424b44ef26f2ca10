"""A results folder read as one pyarrow dataset, through the results store's checks."""

from __future__ import annotations

import shutil

import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from neurocur.analysis import dataset, load
from neurocur.results import ResultsError


def test_a_whole_folder_is_one_dataset_with_condition_and_run(results_dir):
    episodes, modules = load(results_dir)
    table = dataset(results_dir).to_table()
    assert table.num_rows == len(episodes) == 7 * 60                  # 4 curious + 3 random runs of 60 episodes
    counts = table.group_by(["condition", "run"]).aggregate([("episode", "count")]).to_pandas()
    assert sorted(zip(counts["condition"], counts["run"])) == sorted(
        episodes.groupby(["condition", "run"]).size().index)
    assert set(counts["episode_count"]) == {60}
    # one call, filtered by the engine: the same numbers as the store's pandas tables
    curious = dataset(results_dir).to_table(filter=pc.field("condition") == "curious", columns=["da"])
    assert pc.sum(curious["da"]).as_py() == pytest.approx(episodes.loc[episodes["condition"] == "curious", "da"].sum())
    assert dataset(results_dir, "modules").count_rows() == len(modules) == 12 + 3


def test_a_table_no_run_has_is_named(results_dir):
    with pytest.raises(ValueError, match="no run folder holds a table features.parquet"):
        dataset(results_dir, "features")


def test_a_copied_run_folder_is_refused_as_the_store_refuses_it(tmp_path, results_dir):
    copy = tmp_path / "copy"
    shutil.copytree(results_dir, copy)
    shutil.copytree(copy / "runs" / "curious" / "run-000", copy / "runs" / "random_switching" / "run-007")
    with pytest.raises(ResultsError, match="copied or renamed"):
        dataset(copy)


def test_a_table_that_names_another_run_than_its_path_is_refused(tmp_path, results_dir):
    copy = tmp_path / "copy"
    shutil.copytree(results_dir, copy)
    path = copy / "runs" / "curious" / "run-001" / "modules.parquet"
    table = pq.read_table(path)
    pq.write_table(table.set_column(1, "run", pc.add(table["run"], 1)), path)
    with pytest.raises(ResultsError, match=r"say \['curious'\] and \[2\], not run 1 of 'curious'"):
        dataset(copy, "modules")


def test_a_folder_whose_tables_lack_condition_and_run_is_refused_naming_load(tmp_path, results_dir):
    copy = tmp_path / "copy"
    shutil.copytree(results_dir, copy)
    path = copy / "runs" / "curious" / "run-000" / "episodes.parquet"
    pq.write_table(pq.read_table(path).drop_columns(["condition", "run"]), path)
    with pytest.raises(ResultsError, match="no 'condition' and 'run' columns.*neurocur.analysis.load"):
        dataset(copy)
