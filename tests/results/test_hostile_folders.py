"""Hostile results folders and names: links the store did not make, names that would leave the
folder, run folders spelled twice or brought in from elsewhere, a folder that lost its config.toml."""

import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.experiments import load_experiment, run_experiment
from neurocur.results import ResultsError, ResultsStore, RunResult, load
from neurocur.results.names import condition_label
from neurocur.results.safeio import UnsafePath, atomic_text

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"
CIRCUIT = ROOT / "neurocur" / "circuits" / "cd_misfa.toml"


def tiny():
    return load_experiment(SYNTHETIC, runs=2, steps=1000)


@contextmanager
def within(seconds):
    """Fail (instead of hanging) when the block takes longer than ``seconds``."""
    def expired(signum, frame):
        raise TimeoutError(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def experiment(tmp_path, conditions, sweep=""):
    path = tmp_path / "exp.toml"
    path.write_text(f'circuit = "{CIRCUIT}"\nruns = 1\nsteps = 300\nseed = 1\n'
                    f'[world]\ncontexts = ["S-A", "S-B"]\n{sweep}\n{conditions}')
    return path


def result(condition, run=0, value=1.0):
    frame = pd.DataFrame({"condition": [condition], "run": [run], "episode": [0], "x": [value]})
    return RunResult(condition, run, frame, frame.rename(columns={"episode": "module"}),
                     {"condition": condition, "run": run})


# --- links the store did not make ---------------------------------------------------------------

def test_a_symlinked_lock_is_refused_and_its_target_left_alone(tmp_path, capsys):
    out, victim = tmp_path / "out", tmp_path / "victim.txt"
    out.mkdir()
    victim.write_text("precious\n")
    (out / ".lock").symlink_to(victim)
    with pytest.raises(UnsafePath, match=r"\.lock is a symbolic link"):
        with ResultsStore(out).writing():
            pass
    argv = ["run", str(SYNTHETIC), "--runs", "1", "--steps", "200", "--out", str(out), "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert ".lock is a symbolic link" in err and err.count("\n") == 1
    assert victim.read_text() == "precious\n"
    dangling = tmp_path / "created-by-the-lock"
    (out / ".lock").unlink()
    (out / ".lock").symlink_to(dangling)
    with pytest.raises(UnsafePath):
        with ResultsStore(out).writing():
            pass
    assert not dangling.exists()


def test_a_hard_linked_lock_and_planted_temporary_links_are_refused(tmp_path):
    out, victim = tmp_path / "out", tmp_path / "victim.txt"
    out.mkdir()
    victim.write_text("precious\n")
    os.link(victim, out / ".lock")
    with pytest.raises(UnsafePath, match="another hard link"):
        with ResultsStore(out).writing():
            pass
    (out / ".lock").unlink()
    (out / ".partial").symlink_to(tmp_path)  # run tables would land beside the results folder
    with pytest.raises(UnsafePath, match=r"\.partial: expected a folder written by neurocur, got a symbolic link"):
        ResultsStore(out).write_run(result("c"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "victim.txt"]


def test_a_failed_atomic_write_leaves_no_temporary_file(tmp_path, monkeypatch):
    path = tmp_path / "config.toml"
    monkeypatch.setattr(os, "replace", lambda *a: (_ for _ in ()).throw(OSError(27, "File too large")))
    with pytest.raises(OSError, match="File too large"):
        atomic_text(path, "x = 1\n")
    assert list(tmp_path.iterdir()) == []


# --- names that become folders ------------------------------------------------------------------

@pytest.mark.parametrize("name", ["../../x", "..", ".", "", "a/b", ".hidden", "x" * 300, "a@b"])
def test_a_condition_name_that_is_no_folder_name_is_refused_at_load(tmp_path, name):
    path = experiment(tmp_path, f"[conditions.{json.dumps(name)}]\n")
    with pytest.raises(ConfigError, match="expected a name of at most 200 characters") as info:
        load_experiment(path)
    assert info.value.source == str(path) and info.value.key == f"conditions.{name}"


def test_the_store_refuses_to_write_a_run_outside_its_folder_at_once(tmp_path):
    out = tmp_path / "deep" / "out"
    out.mkdir(parents=True)
    (tmp_path / "x" / "run-000").mkdir(parents=True)  # where runs/../../x/run-000 would go
    (tmp_path / "x" / "run-000" / "keep").write_text("")
    with within(10):
        with pytest.raises(ConfigError, match="key 'condition'"):
            ResultsStore(out).write_run(result("../../x"))
    assert [p.name for p in (tmp_path / "x" / "run-000").iterdir()] == ["keep"]
    assert not (out / "runs").exists()


def test_sweep_labels_are_distinct_for_distinct_values_and_do_not_depend_on_key_order(tmp_path):
    sweep = '[sweep]\n"PFC.discount" = [0.5, 0.9]\n"HPC.threshold" = [0.3]\n'
    a = load_experiment(experiment(tmp_path, "", sweep))
    b = load_experiment(experiment(tmp_path, "", sweep.replace('"PFC.discount" = [0.5, 0.9]\n', "") +
                                   '"PFC.discount" = [0.5, 0.9]\n'))
    assert list(a.conditions) == list(b.conditions) == [
        "default@HPC.threshold=0.3,PFC.discount=0.5", "default@HPC.threshold=0.3,PFC.discount=0.9"]
    assert condition_label("c", {"world.file": "d/x.npy"}, "f") == "c@world.file=d%2Fx.npy"
    assert condition_label("c", {"world.file": "d_x.npy"}, "f") == "c@world.file=d_x.npy"


def test_a_label_collision_is_a_config_error_naming_both_points():
    class Taken:
        sweep = {"X.a": "1"}

    with pytest.raises(ConfigError, match=r"the points \{'X.a': '1'\} and \{'X.a': 1\}, both labelled 'c@X.a=1'"):
        condition_label("c", {"X.a": 1}, "exp.toml", {"c@X.a=1": Taken()})


# --- the folder is the truth --------------------------------------------------------------------

def test_a_folder_with_runs_but_no_config_toml_is_refused(folder):
    (folder / "config.toml").unlink()
    with pytest.raises(ResultsError, match="holds runs but no config.toml"):
        load(folder)
    with pytest.raises(ResultsError, match="holds runs but no config.toml"):
        run_experiment(load_experiment(SYNTHETIC, runs=3, steps=2000), folder, jobs=1, conditions=["curious"],
                       progress=False)
    assert not (folder / "config.toml").exists() and not (folder / "runs" / "curious" / "run-002").exists()


@pytest.mark.parametrize("spelling", ["run-1", "run-0_01", "run-0001"])
def test_a_run_number_spelled_twice_is_refused(folder, spelling):
    shutil.copytree(folder / "runs" / "curious" / "run-001", folder / "runs" / "curious" / spelling)
    with pytest.raises(ResultsError, match=rf"{spelling} is not spelled run-<NNN>"):
        load(folder)
    with pytest.raises(ResultsError, match=rf"{spelling} is not spelled"):
        run_experiment(tiny(), folder, jobs=1, conditions=["curious"], progress=False)


def test_a_symlinked_run_folder_is_refused(folder):
    (folder / "runs" / "curious" / "run-002").symlink_to(folder / "runs" / "curious" / "run-001")
    with pytest.raises(ResultsError, match="run-002 is a symbolic link"):
        load(folder)


@pytest.mark.parametrize("change, key", [
    (lambda info: {**info, "steps": 2000}, "steps"),
    (lambda info: {**info, "seed": {**info["seed"], "entropy": 7}}, "seed"),
    (lambda info: {k: v for k, v in info.items() if k != "steps"}, "steps"),
    (lambda info: {}, "condition"),
    (lambda info: {**info, "run": 1.0}, "run"),
    (lambda info: {**info, "run": True}, "run"),
])
def test_a_foreign_or_malformed_run_json_is_refused_naming_the_key(folder, change, key):
    path = folder / "runs" / "curious" / "run-001" / "run.json"
    path.write_text(json.dumps(change(json.loads(path.read_text()))))
    with pytest.raises(ResultsError, match=rf"run-001/run.json: key '{key}'"):
        load(folder)
    with pytest.raises(ResultsError, match=rf"key '{key}'"):
        run_experiment(tiny(), folder, jobs=1, conditions=["curious"], progress=False)


def test_a_run_brought_in_from_a_folder_with_other_steps_is_refused(folder, tmp_path):
    other = tmp_path / "other"
    run_experiment(load_experiment(SYNTHETIC, runs=2, steps=600), other, jobs=1, conditions=["curious"],
                   progress=False)
    shutil.rmtree(folder / "runs" / "curious" / "run-001")
    shutil.copytree(other / "runs" / "curious" / "run-001", folder / "runs" / "curious" / "run-001")
    with pytest.raises(ResultsError, match=r"key 'steps': expected 1000 as this folder's config.toml says, got 600"):
        load(folder)


def test_changed_tables_are_refused_by_their_digest(folder):
    path = folder / "runs" / "curious" / "run-000" / "episodes.parquet"
    table = pd.read_parquet(path)
    table.iloc[:4].to_parquet(path, index=False)
    with pytest.raises(ResultsError, match=r"key 'tables'.*episodes.parquet changed"):
        load(folder)


def test_a_folder_moved_mid_run_is_not_recreated_behind_the_move(folder, tmp_path):
    moved = tmp_path / "moved"
    folder.rename(moved)
    with pytest.raises(UnsafePath, match="does not exist any more"):
        ResultsStore(folder).write_run(result("curious", 1))
    assert not folder.exists()


def test_a_malformed_config_toml_is_one_error_naming_the_file_and_key(folder):
    path = folder / "config.toml"
    text = path.read_text()
    cases = [(text.replace("\nruns = 2\n", "\n"), "runs", "the key neurocur wrote there"),
             (text.replace("\nruns = 2\n", '\nruns = "3"\n'), "runs", "a positive integer"),
             (re.sub(r"(?m)^code = .*$", 'code = "x"', text), "code", "an array of code fingerprints")]
    for broken, key, expected in cases:
        path.write_text(broken)
        with pytest.raises(ConfigError) as info:
            run_experiment(tiny(), folder, jobs=1, conditions=["curious"], progress=False)
        assert (info.value.source, info.value.key) == (str(path), key) and expected in info.value.expected
    path.write_text("a = " + "[" * 3000 + "]" * 3000 + "\n")
    with pytest.raises(ConfigError, match=r"config.toml: expected the resolved experiment neurocur wrote"):
        load(folder)
    path.write_text("runs = = 2\n")
    with pytest.raises(ConfigError, match=r"config.toml: expected the resolved experiment neurocur wrote .*TOML"):
        load(folder)


def test_a_run_json_records_the_digest_of_its_tables(written):
    info = json.loads((written / "runs" / "curious" / "run-000" / "run.json").read_text())
    assert sorted(info["tables"]) == ["episodes.parquet", "modules.parquet"]
    assert all(len(v) == 64 for v in info["tables"].values())


def test_a_read_only_folder_reports_the_failed_write_not_the_lock(folder, monkeypatch):
    """Made read-only mid-run: the summary's write fails, and so does the removal of the lock file
    on the way out; the error reported is the first (a lock file nobody holds never blocks)."""
    def refuse(path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))

    with pytest.raises(PermissionError, match=r"\.summary\.json\.\d+\.tmp"):
        with ResultsStore(folder).writing():
            monkeypatch.setattr(os, "unlink", refuse)
            monkeypatch.setattr(os, "open", refuse)
            ResultsStore(folder).write_summary({})
    monkeypatch.undo()
    with ResultsStore(folder).writing() as lock:  # the lock is free again
        assert lock.stale["pid"] == os.getpid()


def test_a_file_size_limit_leaves_no_temporary_file_and_names_the_file(tmp_path):
    out = tmp_path / "out"
    out.mkdir()

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))  # ulimit -f 4: config.toml does not fit

    done = subprocess.run([sys.executable, "-m", "neurocur.cli", "run", "synthetic", "--runs", "1", "--steps", "200",
                           "--out", str(out), "--no-progress"], capture_output=True, text=True, timeout=120,
                          preexec_fn=limit, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 2
    assert done.stderr == f"neurocur run: error: [Errno 27] cannot write {out / 'config.toml'}: File too large\n"
    assert list(out.iterdir()) == []


def test_a_run_json_naming_a_condition_outside_the_folder_is_refused_without_looking_there(folder):
    path = folder / "runs" / "curious" / "run-001" / "run.json"
    path.write_text(json.dumps({**json.loads(path.read_text()), "condition": "../../elsewhere"}))
    with pytest.raises(ResultsError, match=r"holds run 1 of condition '../../elsewhere' by its run.json.*; remove it$"):
        load(folder)


def test_a_folder_written_before_table_digests_is_read_and_its_steps_still_checked(folder):
    config = folder / "config.toml"
    config.write_text(re.sub(r", plugins = \[\]", "", config.read_text()))  # code fingerprints as written before
    for path in folder.glob("runs/*/*/run.json"):
        info = json.loads(path.read_text())
        path.write_text(json.dumps({k: v for k, v in info.items() if k != "tables"}))
    assert len(load(folder)[0]) > 0
    path = folder / "runs" / "curious" / "run-001" / "run.json"
    path.write_text(json.dumps({**json.loads(path.read_text()), "steps": 2000}))
    with pytest.raises(ResultsError, match="key 'steps'"):
        load(folder)


def test_runs_into_a_fits_output_folder_are_refused_and_leave_it_as_it_was(tmp_path):
    fit_folder = tmp_path / "fit"
    fit_folder.mkdir()
    (fit_folder / "manifest.json").write_text('{"command": "fit", "complete": true, "files": {}}')
    (fit_folder / "fit.csv").write_text("param,value\n")
    before = sorted(p.name for p in fit_folder.iterdir())
    with pytest.raises(ResultsError, match=r"is the output folder of a fit \(manifest.json\), not a results folder"):
        run_experiment(load_experiment(SYNTHETIC, runs=1, steps=2000), fit_folder, jobs=1, conditions=["curious"],
                       progress=False)
    assert sorted(p.name for p in fit_folder.iterdir()) == before
