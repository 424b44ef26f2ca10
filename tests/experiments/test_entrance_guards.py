"""The experiment entrance never hangs without output nor shows a traceback: a FIFO, deep TOML, a
scheduler address that is no Dask scheduler, a huge --runs; and the names the command line offers."""

import http.server
import os
import resource
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.config.npy import load_npy
from neurocur.experiments import load_experiment, run_experiment
from neurocur.experiments.catalog import catalog
from neurocur.experiments.pending import Pending
from neurocur.experiments.pool import LocalPool
from neurocur.experiments.probe import probe_scheduler
from neurocur.experiments.spec import resolve_experiment
from neurocur.tables import resolve_file, shipped_files

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"


def in_thread(fn, seconds):
    """``fn()``'s exception (or None) when it ends within ``seconds``; fails the test when it hangs."""
    outcome = []

    def target():
        try:
            fn()
            outcome.append(None)
        except BaseException as exc:
            outcome.append(exc)

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), f"still running after {seconds} s"
    return outcome[0]


# --- files that are no experiment files ---------------------------------------------------------

def test_a_fifo_is_refused_as_an_experiment_file_at_once(tmp_path, capsys):
    fifo = tmp_path / "exp.toml"
    os.mkfifo(fifo)
    error = in_thread(lambda: load_experiment(fifo), 10)
    assert isinstance(error, ConfigError) and "expected a TOML file (a regular file), got a FIFO" in str(error)
    assert in_thread(lambda: main(["run", str(fifo), "--out", str(tmp_path / "out")]), 10) is None
    err = capsys.readouterr().err
    assert f"{fifo}: expected a TOML file (a regular file)" in err and err.count("\n") == 1


@pytest.mark.parametrize("nested", ["[" * 3000 + "]" * 3000, "{a = " * 3000 + "1" + "}" * 3000])
def test_deeply_nested_toml_is_one_line_exit_2(tmp_path, capsys, nested):
    path = tmp_path / "deep.toml"
    path.write_text(f'name = "deep"\nvalue = {nested}\n')
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err == f"neurocur run: error: {path}: expected valid TOML, got arrays or tables nested too deeply to read\n"


def test_a_folder_named_like_a_shipped_experiment_does_not_shadow_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "icub").mkdir()  # e.g. left by --out icub
    assert resolve_experiment("icub") == shipped_files("experiment")["icub"]
    assert resolve_experiment("./icub") == Path("./icub")  # a path stays a path
    (tmp_path / "mine").mkdir()
    with pytest.raises(ConfigError, match="expected a TOML file, got a directory"):
        load_experiment("mine")


# --- names the command line offers ---------------------------------------------------------------

def test_list_shows_every_shipped_experiment_and_circuit_on_one_line(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out.splitlines()
    names = {line.split()[0] for line in out if line.startswith("  ")}
    assert names == {*shipped_files("experiment"), *shipped_files("invariance"), *shipped_files("circuit")}
    assert {"synthetic", "icub", "invariance", "cd_misfa"} <= names
    kinds = ("experiment", "invariance", "circuit")
    assert len(out) == 3 + sum(len(shipped_files(kind)) for kind in kinds)  # a heading per kind, a line per name


def test_every_experiment_name_offered_to_run_loads_and_invariance_is_offered_to_its_own_command(capsys):
    offered = catalog()["experiment"]
    assert "invariance" not in offered and "synthetic" in offered
    for name in offered:
        assert load_experiment(name, runs=1, steps=10).conditions
    assert main(["run", "no_such_experiment"]) == 2
    err = capsys.readouterr().err
    assert "synthetic" in err and "invariance" not in err
    assert resolve_file("invariance", Path(), "invariance", source="x", key=None).name == "invariance.toml"


# --- a scheduler address that is no Dask scheduler ---------------------------------------------

class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def test_an_http_server_as_scheduler_is_refused_within_the_timeout(tmp_path):
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Quiet)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    address = f"tcp://127.0.0.1:{server.server_address[1]}"
    try:
        started = time.monotonic()
        error = in_thread(lambda: probe_scheduler(address, timeout=1.0), 10)
        assert isinstance(error, ValueError) and "sent no Dask handshake within 1 s" in str(error)
        assert time.monotonic() - started < 5
        exp = load_experiment(SYNTHETIC, runs=1, steps=200)
        error = in_thread(lambda: run_experiment(exp, tmp_path / "out", conditions=["curious"], progress=False,
                                                 scheduler=address), 60)
        assert isinstance(error, ValueError) and f"--scheduler {address}: expected a reachable dask" in str(error)
    finally:
        server.shutdown()
        server.server_close()


def test_a_listener_that_answers_garbage_or_hangs_up_is_refused():
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen()
        address = f"127.0.0.1:{listener.getsockname()[1]}"

        def answer():
            conn, _ = listener.accept()
            conn.sendall(b"SSH-2.0-OpenSSH_9.6\r\n")
            conn.close()

        threading.Thread(target=answer, daemon=True).start()
        error = in_thread(lambda: probe_scheduler(address, timeout=1.0), 10)
        assert isinstance(error, ValueError) and "expected a reachable dask.distributed scheduler" in str(error)


# --- a huge --runs streams its seeds -------------------------------------------------------------

def test_a_huge_number_of_runs_starts_at_once(tmp_path):
    runs = 100_000_000
    exp = load_experiment(SYNTHETIC, runs=runs, steps=200)
    started = time.monotonic()
    resolved = exp.resolved()
    assert resolved["seeds"] == {"entropy": exp.seed, "spawn_key": "[run]"}
    curious = exp.conditions["curious"]
    todo = Pending([curious], runs, {("curious", 0), ("curious", 7), ("other", 1)})
    assert len(todo) == runs - 2 and todo.first_of_each() == {"curious": (curious, 1)}
    assert [i for _, i in zip(range(8), todo)] == [(curious, i) for i in (1, 2, 3, 4, 5, 6, 8, 9)]
    assert time.monotonic() - started < 2

    seen = {}

    class Counting(LocalPool):  # the local pool's pre-flight, its compute replaced by a look at todo
        def compute(self, exp, todo, store, bar, ctrl_c, **options):
            seen["todo"] = len(todo)
            seen["first"] = next(iter(todo))[1]

    started = time.monotonic()
    run_experiment(exp, tmp_path / "out", conditions=["curious"], progress=False, executor=Counting(1))
    assert seen == {"todo": runs, "first": 0}
    assert time.monotonic() - started < 30
    assert (tmp_path / "out" / "config.toml").stat().st_size < 200_000


# --- files and settings that would exhaust memory ----------------------------------------------

def lying_npy(path, claimed_rows):
    """A .npy file holding 4 x 2 float64 zeros whose header claims ``claimed_rows`` rows."""
    with open(path, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (claimed_rows, 2)})
        fh.write(np.zeros((4, 2)).tobytes())
    return path


def test_a_npy_header_claiming_a_huge_shape_is_refused_before_any_allocation(tmp_path, capsys):
    path = lying_npy(tmp_path / "huge.npy", 4_500_000_000_000)  # 72 TB of float64
    with pytest.raises(ValueError, match=r"header claims \(shape \(4500000000000, 2\), float64\), got 64 bytes"):
        load_npy(path)
    assert main(["omega", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"omega: {path}: expected a .npy file holding the 72000000000000 bytes" in err and err.count("\n") == 1
    exp = tmp_path / "own.toml"
    exp.write_text(f'circuit = "cd_misfa"\nruns = 1\nsteps = 100\nseed = 1\n[world]\ncontexts = ["S-X", "S-A"]\n'
                   f'[world.sources]\nS-X = "{path.name}"\n')
    with pytest.raises(ConfigError, match=r"own.toml: key 'world.sources.S-X': expected a .npy file written by "
                                          r"numpy.save, got .* \(expected a .npy file holding the 72000000000000 bytes"):
        load_experiment(exp)


def test_omega_of_a_signal_too_large_for_float64_is_one_line(tmp_path, capsys):
    path = tmp_path / "scaled.npy"
    np.save(path, np.random.default_rng(0).normal(size=(200, 3)) * 1e160)
    assert main(["omega", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"omega: {path}: expected a signal whose variance is finite in float64" in err and err.count("\n") == 1


def test_a_frame_shape_beyond_the_memory_limit_is_one_line_exit_2(tmp_path):
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))

    done = subprocess.run(
        [sys.executable, "-m", "neurocur.cli", "run", "synthetic", "--runs", "1", "--steps", "100", "--no-progress",
         "--set", "world.frame_shape=[100000, 100000]", "--out", str(tmp_path / "out")],
        capture_output=True, text=True, timeout=120, preexec_fn=limit, cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 2, done.stderr[-2000:]
    assert done.stderr.startswith("neurocur run: error: out of memory") and done.stderr.count("\n") == 1


def test_a_name_of_another_kind_points_to_neurocur_list_and_deep_set_values_are_one_line(capsys):
    assert main(["run", "invariance"]) == 2
    err = capsys.readouterr().err
    assert "got 'invariance' (a shipped invariance file: 'neurocur list' says how to use it)" in err
    assert err.count("\n") == 1
    assert main(["run", "synthetic", "--set", "HPC.threshold=" + "[" * 3000 + "]" * 3000]) == 2
    err = capsys.readouterr().err
    assert err == "neurocur run: error: --set: expected a TOML value, got arrays or tables nested too deeply to read\n"
