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
