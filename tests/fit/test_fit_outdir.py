"""A fit command's output folder: never a results folder nor the input, locked, replaced whole with a manifest,
and an interrupted command says so (exit 130, manifest complete: false, a partial table named partial)."""

from __future__ import annotations

import hashlib
import json
import signal
import subprocess
import sys

import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.experiments import load_experiment
from neurocur.fit.recovery import simulate

FIT = ["--experiment", "free_choice", "--condition", "learning_progress", "--fit", "LC.gain",
       "--bounds", "LC.gain=0:60", "--starts", "1"]
RECOVER = ["recover", "free_choice", "--condition", "learning_progress", "--fit", "LC.gain", "--bounds",
           "LC.gain=2:40", "--signal", "HPC=error", "--datasets", "3", "--episodes", "30", "--starts", "1"]


def _table(path, seed: int, n: int = 40):
    condition = load_experiment("free_choice").conditions["learning_progress"]
    _, episodes = simulate(condition, {"LC.gain": 20.0}, seed, n, signal=("HPC", "error"))
    pd.DataFrame({"dataset": f"s{seed}", "episode": episodes["episode"], "context": episodes["context"],
                  "decision": episodes["next_context"], "error": episodes["error"]}).to_csv(path, index=False)
    return path


@pytest.fixture(autouse=True)
def _ctrl_c_restored():
    """main() ignores a further Ctrl-C after the first; the tests give it back."""
    yield
    signal.signal(signal.SIGINT, signal.default_int_handler)


def _snapshot(root):
    return {p.relative_to(root): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_out_may_not_be_or_lie_inside_a_results_folder_or_the_input(tmp_path, folder, capsys):
    before = _snapshot(folder)
    for out in (folder, folder / "fit", folder / "runs" / "learning_progress"):
        status = main(["fit", str(folder), *FIT, "--out", str(out)])
        err = capsys.readouterr().err.strip()
        assert status == 2 and "\n" not in err and "--out" in err and "results folder" in err, err
    data = _table(tmp_path / "choices.csv", 1)
    status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(folder / "fits")])
    assert status == 2 and "outside any results folder" in capsys.readouterr().err
    assert _snapshot(folder) == before and not (folder / "fit").exists() and not (folder / "fits").exists()
    status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(tmp_path)])  # the input inside
    assert status == 2 and "apart from the input" in capsys.readouterr().err


def test_a_second_fit_replaces_the_first_whole_and_the_manifest_lists_every_file(tmp_path, capsys):
    first, second = _table(tmp_path / "a.csv", 1), _table(tmp_path / "b.csv", 2)
    out = tmp_path / "fit"
    assert main(["fit", str(first), *FIT, "--signal", "HPC=error", "--ci", "bootstrap", "--bootstrap", "3",
                 "--out", str(out)]) == 0
    assert (out / "bootstrap.csv").is_file()
    assert main(["fit", str(second), *FIT, "--signal", "HPC=error", "--out", str(out)]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["complete"] is True and manifest["command"] == "fit" and manifest["arguments"]["data"] == str(second)
    assert sorted(manifest["files"]) == ["fit.csv", "summary.json"]
    assert sorted(p.name for p in out.iterdir()) == ["fit.csv", "manifest.json", "summary.json"]
    for name, digest in manifest["files"].items():
        assert hashlib.sha256((out / name).read_bytes()).hexdigest() == digest
    assert list(pd.read_csv(out / "fit.csv")["dataset"]) == ["s2"]


def test_an_out_holding_other_files_is_refused_and_kept(tmp_path, capsys):
    data = _table(tmp_path / "a.csv", 1)
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "'notes.txt'" in err and "manifest.json" in err and "\n" not in err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_a_second_fit_into_a_locked_out_is_refused(tmp_path, capsys):
    data = _table(tmp_path / "a.csv", 1)
    out = tmp_path / "fit"
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time\nfrom neurocur.results.lock import locked\n"
         "with locked(sys.argv[1]):\n    print('held', flush=True)\n    time.sleep(60)\n", str(out)],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        status = main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(out)])
        err = capsys.readouterr().err
        assert status == 2 and "in use" in err and f"pid {holder.pid}" in err
        assert not (out / "fit.csv").exists()
    finally:
        holder.kill()
        holder.wait()


def test_an_interrupted_recover_marks_its_partial_table(tmp_path, monkeypatch, capsys):
    import neurocur.fit.recovery as recovery

    fit_ml, calls = recovery.fit_ml, []

    def interrupted_at_the_second(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return fit_ml(*args, **kwargs)

    monkeypatch.setattr(recovery, "fit_ml", interrupted_at_the_second)
    out = tmp_path / "rec"
    assert main([*RECOVER, "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "neurocur recover: interrupted; recovery.partial.csv written so far" in err
    assert "finished runs are kept" not in err
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["complete"] is False and list(manifest["files"]) == ["recovery.partial.csv"]
    assert not (out / "recovery.csv").exists() and len(pd.read_csv(out / "recovery.partial.csv")) == 1
    monkeypatch.undo()
    assert main([*RECOVER, "--out", str(out)]) == 0  # run again: the partial table is replaced by the whole one
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "recovery.csv", "recovery.png",
                                                      "recovery_summary.csv"]


@pytest.mark.parametrize("where, message", [("load_data", "nothing written"),
                                            ("fit_data", "no result written in")])
def test_ctrl_c_during_a_fit_says_what_the_fit_left(tmp_path, monkeypatch, capsys, where, message):
    import neurocur.fit.study as study

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(study, where, interrupt)
    data = _table(tmp_path / "a.csv", 1)
    assert main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(tmp_path / "fit")]) == 130
    err = capsys.readouterr().err.strip()
    assert err.startswith("neurocur fit: interrupted; ") and message in err and "finished runs" not in err


def test_another_programs_config_toml_does_not_make_a_results_folder(tmp_path):
    project = tmp_path / "project"
    project.mkdir()
    (project / "config.toml").write_text('title = "my project"\n')
    data = _table(tmp_path / "a.csv", 1)
    assert main(["fit", str(data), *FIT, "--signal", "HPC=error", "--out", str(project / "fit")]) == 0


def test_an_interrupted_compare_marks_its_partial_table(tmp_path, monkeypatch, capsys):
    import neurocur.fit.compare as compare

    score, calls = compare.score, []

    def interrupted_at_the_second_model(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:  # one data set: the first model's table is written, then the second model is stopped
            raise KeyboardInterrupt
        return score(*args, **kwargs)

    monkeypatch.setattr(compare, "score", interrupted_at_the_second_model)
    data = _table(tmp_path / "a.csv", 1)
    out = tmp_path / "compare"
    assert main(["compare", str(data), "--experiment", "free_choice", "--models", "learning_progress", "random",
                 "--fit", "learning_progress:LC.gain", "--bounds", "LC.gain=0:60", "--signal", "HPC=error",
                 "--starts", "1", "--out", str(out)]) == 130
    assert "neurocur compare: interrupted; compare.partial.csv written so far" in capsys.readouterr().err
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["complete"] is False and list(manifest["files"]) == ["compare.partial.csv"]
    assert list(pd.read_csv(out / "compare.partial.csv")["model"]) == ["learning_progress"]
    assert sorted(p.name for p in out.iterdir()) == ["compare.partial.csv", "manifest.json"]
