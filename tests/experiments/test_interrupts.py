"""Ending a ``neurocur run`` abruptly: Ctrl-C once or twice, or the parent killed. Each ends in
correct results (after a resume) and leaves no worker behind; the command runs as a subprocess
in its own session, so that a signal reaches its whole process group as a terminal's would."""

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from neurocur.experiments import load_experiment, run_experiment
from neurocur.results.store import PARTIAL

SYNTHETIC = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml"
#: runs in progress when the first signal comes (each worker's first run also loads the compiled kernels);
#: a run of STEPS takes about 0.7 s here, but one may still end before either signal, so a test counts
#: the runs actually in progress instead of timing them
RUNS, STEPS = 2, 200_000


def start(out, runs=RUNS, steps=STEPS, jobs=2):
    cmd = [sys.executable, "-m", "neurocur.cli", "run", str(SYNTHETIC), "--runs", str(runs), "--steps", str(steps),
           "--jobs", str(jobs), "--out", str(out), "--condition", "curious", "--no-progress"]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)


def processes() -> dict[int, tuple[int, int]]:
    """Every live process: pid -> (parent pid, process group)."""
    found = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != "Z":
            found[int(stat.parent.name)] = (int(fields[1]), int(fields[2]))
    return found


def group(pgid: int) -> list[int]:
    """The live processes of process group ``pgid`` (the command, its fork server and workers)."""
    return [pid for pid, (_, g) in processes().items() if g == pgid]


def command_line(pid: int) -> bytes:
    """The process's command line; empty once it has exited (a child may end between listing and reading)."""
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def workers(pid: int) -> list[int]:
    """The worker processes of the command ``pid``: the children of its fork server."""
    table = processes()
    servers = [p for p, (parent, _) in table.items() if parent == pid and b"forkserver" in command_line(p)]
    return [p for p, (parent, _) in table.items() if parent in servers]


def wait_until(condition, timeout: float, what: str) -> float:
    started = time.monotonic()
    while not condition():
        if time.monotonic() - started > timeout:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)
    return time.monotonic() - started


def workers_running(proc, jobs=2):
    """Wait until the command's workers compute."""
    wait_until(lambda: len(workers(proc.pid)) >= jobs or proc.poll() is not None, 60, "the workers")
    assert proc.poll() is None, proc.stderr.read()
    time.sleep(0.3)  # into the runs


def resume(out):
    # the code is this test's in both processes (accepted in case a file is saved meanwhile)
    run_experiment(load_experiment(SYNTHETIC, runs=RUNS, steps=STEPS), out, jobs=2, conditions=["curious"],
                   progress=False, accept_code_change=True)


def tables(out):
    return {p.relative_to(out): pd.read_parquet(p) for p in sorted(Path(out).glob("runs/*/*/*.parquet"))}


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    out = tmp_path_factory.mktemp("clean") / "out"
    run_experiment(load_experiment(SYNTHETIC, runs=RUNS, steps=STEPS), out, jobs=2, conditions=["curious"],
                   progress=False)
    return tables(out)


def assert_same(a, b):
    assert a.keys() == b.keys() and len(a) == 2 * RUNS
    for key in a:
        pd.testing.assert_frame_equal(a[key], b[key])


def test_a_killed_parent_takes_its_workers_along_and_a_resume_completes(tmp_path, clean):
    out = tmp_path / "out"
    proc = start(out)
    workers_running(proc)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    gone = wait_until(lambda: not group(proc.pid), 10, "the workers to end")
    assert gone < 5
    proc.stderr.close()
    resume(out)  # at once: the dead parent's lock and partial runs do not block
    assert_same(tables(out), clean)
    assert not (out / PARTIAL).exists() and not (out / ".lock").exists()


def test_ctrl_c_twice_abandons_the_runs_at_once(tmp_path, clean):
    out = tmp_path / "out"
    proc = start(out)
    workers_running(proc)
    os.killpg(proc.pid, signal.SIGINT)
    first = proc.stderr.readline()
    announced = re.match(r"neurocur: interrupted; finishing the (\d+) run\(s\) in progress", first)
    assert announced and 1 <= int(announced[1]) <= RUNS, first
    os.killpg(proc.pid, signal.SIGINT)
    sent = time.monotonic()
    _, err = proc.communicate(timeout=20)
    assert proc.returncode == 130 and time.monotonic() - sent < 5
    saved = len(list(out.glob("runs/curious/*/run.json")))  # a run that ended between the signals is kept
    assert saved < RUNS
    assert err == f"neurocur: abandoned the {RUNS - saved} run(s) in progress\n"  # and no traceback
    assert not (out / PARTIAL).exists() and not (out / ".lock").exists()
    wait_until(lambda: not group(proc.pid), 10, "the workers to end")
    resume(out)
    assert_same(tables(out), clean)


def test_ctrl_c_once_finishes_the_runs_in_progress_and_starts_no_other(tmp_path):
    out = tmp_path / "out"
    proc = start(out, runs=3, steps=4 * STEPS, jobs=1)  # a run takes about 2.5 s
    first = out / "runs" / "curious" / "run-000" / "run.json"
    wait_until(lambda: first.is_file() or proc.poll() is not None, 60, "the first run")
    time.sleep(0.3)  # run 1 is submitted as soon as run 0 is done, and takes longer than this
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.count("\n") == 1 and "finishing the 1 run(s) in progress" in err
    assert sorted(p.name for p in (out / "runs" / "curious").iterdir()) == ["run-000", "run-001"]
    assert not (out / PARTIAL).exists()
