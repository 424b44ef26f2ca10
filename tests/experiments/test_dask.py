"""Runs on Dask (dask.distributed): the same tables as the local pool; a lost worker loses nothing."""

import os
import signal
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

from neurocur.experiments import load_experiment, run_experiment
from neurocur.results import ResultsStore

distributed = pytest.importorskip("distributed")

SYNTHETIC = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml"
PAIR = ["curious", "random_switching"]


def tables(out):
    return {p.relative_to(out): pd.read_parquet(p) for p in sorted(Path(out).glob("runs/*/*/*.parquet"))}


def assert_same_tables(a, b):
    ta, tb = tables(a), tables(b)
    assert ta.keys() == tb.keys() and ta
    for key in ta:
        pd.testing.assert_frame_equal(ta[key], tb[key])


@pytest.fixture(scope="module")
def local_reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    run_experiment(load_experiment(SYNTHETIC, runs=3, steps=8000), out, jobs=2, conditions=PAIR, progress=False)
    return out


def test_a_local_cluster_gives_the_local_pools_tables(local_reference, tmp_path):
    out = tmp_path / "dask"
    run_experiment(load_experiment(SYNTHETIC, runs=3, steps=8000), out, jobs=2, conditions=PAIR, progress=False,
                   scheduler="local")
    assert_same_tables(out, local_reference)
    assert len(ResultsStore(out).completed(PAIR, 3)) == 6


def test_a_killed_worker_loses_nothing_once_the_sweep_is_run_again(local_reference, tmp_path):
    out = tmp_path / "killed"
    exp = load_experiment(SYNTHETIC, runs=3, steps=8000)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        failure = []

        def sweep():
            try:
                run_experiment(exp, out, conditions=PAIR, progress=False, scheduler=cluster.scheduler_address)
            except Exception as exc:  # a worker lost at a bad moment may fail the sweep: re-running resumes
                failure.append(exc)

        thread = threading.Thread(target=sweep)
        thread.start()
        deadline = time.monotonic() + 120
        while not list(out.glob("runs/*/*/run.json")) and time.monotonic() < deadline and thread.is_alive():
            time.sleep(0.05)
        victim = next(iter(client.run(os.getpid).values()))
        os.kill(victim, signal.SIGKILL)  # in the middle of the sweep
        thread.join(timeout=180)
        assert not thread.is_alive()
        run_experiment(exp, out, conditions=PAIR, progress=False, scheduler=cluster.scheduler_address)
    assert_same_tables(out, local_reference)


def test_an_unreachable_scheduler_is_a_clear_error(tmp_path):
    exp = load_experiment(SYNTHETIC, runs=1, steps=500)
    with pytest.raises(ValueError, match="--scheduler tcp://127.0.0.1:9: expected a reachable dask.distributed"):
        run_experiment(exp, tmp_path / "out", conditions=["curious"], progress=False, scheduler="tcp://127.0.0.1:9")
