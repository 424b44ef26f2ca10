"""Reading a results folder back (neurocur.results.reading): the folder is the truth, so a run folder
whose run.json or tables name another condition or run than its path is refused, naming both paths."""

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.experiments import load_experiment, run_experiment
from neurocur.results import ResultsError, load
from neurocur.results.reading import join_table, read_table

SYNTHETIC = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml"


def tiny():
    return load_experiment(SYNTHETIC, runs=2, steps=1000)


def tables(out):
    return {p.relative_to(out): pd.read_parquet(p) for p in sorted(Path(out).glob("runs/*/*/*.parquet"))}


def test_a_copied_condition_folder_is_refused_naming_both_paths(folder, capsys):
    shutil.copytree(folder / "runs" / "curious", folder / "runs" / "curious_old")
    with pytest.raises(ResultsError) as info:
        load(folder)
    text = str(info.value)
    assert f"{folder / 'runs' / 'curious_old' / 'run-000'} holds run 0 of condition 'curious'" in text
    assert f"the same run is in {folder / 'runs' / 'curious' / 'run-000'}" in text
    assert main(["figures", str(folder)]) == 2  # no doubled figures either
    err = capsys.readouterr().err
    assert "copied or renamed" in err and err.count("\n") == 1


def test_a_renamed_run_folder_is_refused_and_blocks_a_resume(folder):
    (folder / "runs" / "curious" / "run-001").rename(folder / "runs" / "curious" / "run-005")
    with pytest.raises(ResultsError, match=r"run-005 holds run 1 of condition 'curious' by its run.json.*"
                                           r"rename it to .*run-001"):
        load(folder)
    before = tables(folder)
    with pytest.raises(ResultsError, match="run-005 holds run 1"):  # refused before computing anything
        run_experiment(tiny(), folder, jobs=1, conditions=["curious"], progress=False)
    assert tables(folder).keys() == before.keys()


def test_the_tables_must_agree_with_the_folder_too(folder):
    copy = folder / "runs" / "other" / "run-000"
    shutil.copytree(folder / "runs" / "curious" / "run-000", copy)
    info = json.loads((copy / "run.json").read_text())
    (copy / "run.json").write_text(json.dumps({**info, "condition": "other"}))  # run.json made to agree
    with pytest.raises(ResultsError, match="other/run-000 holds run 0 of condition 'curious' by its episodes.parquet"):
        load(folder)


def test_a_per_run_table_is_joined_led_by_the_folders_condition_and_run(tmp_path):
    runs = tmp_path / "runs"
    folders = [runs / "a" / "run-000", runs / "a" / "run-001", runs / "b" / "run-000"]
    for folder in folders:
        folder.mkdir(parents=True)
    pd.DataFrame({"module": [0, 1], "x": [0.5, 1.5]}).to_parquet(folders[0] / "features.parquet")
    pd.DataFrame({"module": [], "x": []}).to_parquet(folders[1] / "features.parquet")  # empty: left out
    pd.DataFrame({"module": [3], "x": [2.5]}).to_parquet(folders[2] / "features.parquet")
    joined = join_table(folders, "features")
    assert list(joined.columns) == ["condition", "run", "module", "x"]
    assert joined.values.tolist() == [["a", 0, 0, 0.5], ["a", 0, 1, 1.5], ["b", 0, 3, 2.5]]
    empty = join_table(folders[1:2], "features", ["condition", "run", "module"])
    assert empty.empty and list(empty.columns) == ["condition", "run", "module"]
    assert join_table(folders, "other", ["a"]).columns.tolist() == ["a"]  # no run has it


def test_a_per_run_table_naming_another_run_is_refused(tmp_path):
    folder = tmp_path / "runs" / "a" / "run-002"
    folder.mkdir(parents=True)
    pd.DataFrame({"run": [1, 1], "x": [0.0, 1.0]}).to_parquet(folder / "features.parquet")
    with pytest.raises(ResultsError) as info:
        read_table(folder, "features")
    assert str(info.value) == (f"run folder {folder} holds run 1 of condition 'a' by its features.parquet, not run 2 of "
                               f"'a' as its path says (a copied or renamed folder?); rename it to "
                               f"{tmp_path / 'runs' / 'a' / 'run-001'} or remove it")
