"""The results store's guarantees: the folder is the truth, one writer at a time, fingerprinted
inputs and code, runs that are never written half or twice."""

import hashlib
import shutil
import signal
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError, ParamSpec, param, path_values, spec_param
from neurocur.experiments import load_experiment, run_experiment
from neurocur.experiments import pool as pool_module
from neurocur.results import FolderInUse, ResultsError, ResultsStore, RunResult, load
from neurocur.results.store import PARTIAL

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"
RUNS, STEPS = 2, 1000


def tiny():
    return load_experiment(SYNTHETIC, runs=RUNS, steps=STEPS)


def tables(out):
    return {p.relative_to(out): pd.read_parquet(p) for p in sorted(Path(out).glob("runs/*/*/*.parquet"))}


# --- runs written whole, once (the reading checks: test_reading.py) ---------------------------

def test_a_run_without_its_run_json_is_computed_again(folder, written):
    (folder / "runs" / "curious" / "run-001" / "run.json").unlink()
    with pytest.raises(ResultsError, match=r"run-001 is incomplete: it lacks run.json"):
        load(folder)
    run_experiment(tiny(), folder, jobs=1, conditions=["curious"], progress=False)
    a, b = tables(folder), tables(written)
    assert a.keys() == b.keys()
    for key in a:
        pd.testing.assert_frame_equal(a[key], b[key])
    assert not (folder / PARTIAL).exists()


def test_a_run_written_twice_keeps_the_complete_folder_and_replaces_an_incomplete_one(tmp_path):
    store = ResultsStore(tmp_path)

    def result(value):
        frame = pd.DataFrame({"condition": ["c"], "run": [0], "episode": [0], "x": [value]})
        return RunResult("c", 0, frame, frame.rename(columns={"episode": "module"}), {"condition": "c", "run": 0})

    final = store.write_run(result(1.0))
    assert store.write_run(result(2.0)) == final  # an orphan's late copy of a finished run
    assert pd.read_parquet(final / "episodes.parquet")["x"].tolist() == [1.0]
    (final / "run.json").unlink()  # incomplete: replaced
    store.write_run(result(3.0))
    assert pd.read_parquet(final / "episodes.parquet")["x"].tolist() == [3.0] and (final / "run.json").is_file()
    assert list((tmp_path / PARTIAL).iterdir()) == []


# --- one writer at a time ---------------------------------------------------------------------

HOLD = """
import sys, time
from neurocur.results import ResultsStore
with ResultsStore(sys.argv[1]).writing():
    print("locked", flush=True)
    time.sleep(60)
"""


def test_a_second_writer_is_refused_naming_the_holder_and_a_dead_holder_never_blocks(tmp_path, capsys):
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(FolderInUse, match=rf"{out} is in use: pid {holder.pid} on .* is writing to it"):
            run_experiment(tiny(), out, jobs=1, conditions=["curious"], progress=False)
        argv = ["run", str(SYNTHETIC), "--runs", "1", "--steps", "200", "--out", str(out), "--no-progress"]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert f"is in use: pid {holder.pid}" in err and err.count("\n") == 1
        assert not (out / "config.toml").exists()
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.communicate()
    with ResultsStore(out).writing() as lock:  # the OS released the dead holder's lock
        assert lock.stale["pid"] == holder.pid
        with ResultsStore(out).writing():  # re-entrant within a process
            pass
    assert not (out / ".lock").exists()


# --- fingerprints -----------------------------------------------------------------------------

def own_source_experiment(tmp_path, rows=1000, contexts='["S-X", "S-A", "S-D"]'):
    t = np.arange(rows) / rows * 2 * np.pi
    np.save(tmp_path / "x.npy", np.stack([np.sin(3 * t), np.cos(40 * t)], axis=1))
    path = tmp_path / "own.toml"
    path.write_text(f'name = "own"\ncircuit = "{ROOT / "neurocur" / "circuits" / "cd_misfa.toml"}"\nruns = 1\nsteps = 300\n'
                    f'seed = 1\n\n[world]\ncontexts = {contexts}\n\n[world.sources]\nS-X = "x.npy"\n')
    return path


@dataclass(frozen=True)
class _Inner:
    file: str = param("a.npy", str, path=True)


@dataclass(frozen=True)
class _Outer:
    name: str = param("x", str)
    files: tuple = spec_param((), ParamSpec.sequence(ParamSpec(str, path=True)))
    table: dict = spec_param({}, ParamSpec.table(ParamSpec(str, path=True, classes=(np.ndarray,))))
    inner: _Inner = spec_param(_Inner(), ParamSpec.nested(_Inner))
    cache: str | None = param(None, str, optional=True, path=True)


def test_path_values_walks_lists_tables_and_nested_parameters():
    params = _Outer(files=("b.npy", "c.npy"), table={"S-X": "d.npy", "S-Y": np.zeros((3, 2))})
    assert path_values(params) == ["b.npy", "c.npy", "d.npy", "a.npy"]


def test_a_changed_input_file_is_refused_naming_it(tmp_path):
    path, out = own_source_experiment(tmp_path), tmp_path / "out"
    source = tmp_path / "x.npy"
    run_experiment(load_experiment(path), out, jobs=1, progress=False)
    old = hashlib.sha256(source.read_bytes()).hexdigest()
    config = tomllib.loads((out / "config.toml").read_text())
    assert config["conditions"]["default"]["inputs"] == {str(source): old}
    np.save(source, np.load(source)[:, ::-1])  # same shape, other content
    with pytest.raises(ResultsError) as info:
        run_experiment(load_experiment(path), out, jobs=1, progress=False)
    assert f"input file {source} changed" in str(info.value) and old[:12] in str(info.value)
    assert "use another --out folder" in str(info.value)


def test_the_code_fingerprint_covers_the_code_that_computes_runs_and_not_the_analysis(tmp_path, monkeypatch):
    """A copy of the package: a changed analysis module leaves the source hash alone (it only reads
    results folders), and so does a changed module of neurocur.rl (no run imports it); a changed
    region module, which computes runs, changes it."""
    from neurocur.results import fingerprint

    copy = tmp_path / "neurocur"
    shutil.copytree(fingerprint.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(fingerprint, "PACKAGE", copy)

    def source():
        return fingerprint._package_fingerprint.__wrapped__()["source"]

    before = source()
    for module, same in (("analysis/stats/report.py", True), ("rl/wrappers.py", True), ("regions/vta.py", False)):
        path = copy / module
        path.write_text(path.read_text() + "\n# one more line\n")
        assert (source() == before) is same, module


def test_changed_code_is_refused_unless_accepted(folder, capsys):
    config = folder / "config.toml"
    text = config.read_text()
    recorded = tomllib.loads(text)["code"]
    assert len(recorded) == 1 and recorded[0]["version"] and len(recorded[0]["source"]) == 16
    config.write_text(text.replace(recorded[0]["source"], "0123456789abcdef"))  # as if other code wrote the runs
    argv = ["run", str(SYNTHETIC), "--runs", str(RUNS), "--steps", str(STEPS), "--out", str(folder),
            "--condition", "curious", "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "the code changed since this folder's runs were computed" in err and "source 01234567 then" in err
    assert "--accept-code-change" in err and err.count("\n") == 1
    assert main([*argv, "--accept-code-change"]) == 0
    sources = [c["source"] for c in tomllib.loads(config.read_text())["code"]]
    assert sources == ["0123456789abcdef", recorded[0]["source"]]  # every code that wrote runs here


def test_a_different_experiment_is_still_refused_by_key(folder):
    with pytest.raises(ConfigError) as info:
        run_experiment(load_experiment(SYNTHETIC, runs=RUNS, steps=STEPS + 1), folder, jobs=1, progress=False)
    assert info.value.key == "steps"


# --- checks before any worker starts ----------------------------------------------------------

@pytest.fixture
def no_workers(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("a worker pool was started")

    monkeypatch.setattr(pool_module, "ProcessPoolExecutor", refuse)


def test_a_source_longer_than_hpc_n_states_fails_before_any_worker(tmp_path, capsys, no_workers):
    path = own_source_experiment(tmp_path, rows=1500, contexts='["S-X", "S-X"]')
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "condition 'default': HPC: n_states = 1000 is smaller than the world's 1500 context-states" in err
    assert err.count("\n") == 1 and not out.exists()


def test_the_memory_estimate_is_refused_above_the_limit(tmp_path, capsys, no_workers):
    out = tmp_path / "out"
    argv = ["run", str(SYNTHETIC), "--runs", "2", "--steps", "200", "--jobs", "2", "--out", str(out),
            "--condition", "curious", "--max-memory", "300M", "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "the runs would need about" in err and "2 workers x" in err
    assert "estimated from the first episode of condition 'curious'), more than --max-memory allows (300 MB)" in err
    assert err.count("\n") == 1 and not out.exists()
