"""Executors: the runner computes through whichever it is given, and holds the folder's lock itself."""

from pathlib import Path

import pandas as pd

from neurocur.experiments import load_experiment, run_experiment, run_one
from neurocur.experiments.cluster import DaskCluster
from neurocur.experiments.executors import executor_for
from neurocur.experiments.pool import LocalPool
from neurocur.results.lock import LOCK

SYNTHETIC = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml"


class InProcess:
    """An executor of the protocol written here: every run computed in this process, in order."""

    def __init__(self):
        self.started, self.computed = 0, []

    def start(self):
        self.started += 1

    def workers(self, runs):
        return 1

    def compute(self, exp, todo, store, bar, ctrl_c, *, checkpoint_every=None, save_agent=False):
        for c, i in todo:
            self.computed.append((c.name, i))
            store.write_run(run_one(c, i, exp.steps, exp.run_seed(i), save_agent=save_agent))
            bar.update(1)


def tables(out):
    return {p.relative_to(out): pd.read_parquet(p) for p in sorted(Path(out).glob("runs/*/*/*.parquet"))}


def test_the_runner_computes_through_any_executor_with_the_same_tables(tmp_path):
    exp = load_experiment(SYNTHETIC, runs=2, steps=400)
    mine = InProcess()
    finished = []

    def finish(folder):  # called with the folder's lock still held (a released lock removes its file)
        finished.append((folder, (folder / LOCK).is_file()))

    run_experiment(exp, tmp_path / "mine", conditions=["curious"], progress=False, executor=mine, finish=finish)
    assert mine.started == 1 and mine.computed == [("curious", 0), ("curious", 1)]
    assert finished == [(tmp_path / "mine", True)] and not (tmp_path / "mine" / LOCK).exists()
    run_experiment(exp, tmp_path / "pool", conditions=["curious"], progress=False, jobs=1)
    mine_tables, pool_tables = tables(tmp_path / "mine"), tables(tmp_path / "pool")
    assert list(mine_tables) == list(pool_tables) and len(mine_tables) == 4
    for key, table in mine_tables.items():
        pd.testing.assert_frame_equal(table, pool_tables[key])
    again = InProcess()  # nothing left to do: nothing is started or computed
    run_experiment(exp, tmp_path / "mine", conditions=["curious"], progress=False, executor=again)
    assert (again.started, again.computed) == (0, [])


def test_executor_for_picks_the_executor_of_scheduler_and_jobs():
    local = executor_for(None, 3)
    assert isinstance(local, LocalPool) and (local.workers(2), local.workers(10)) == (2, 3)
    dask = executor_for("local", 2)
    assert isinstance(dask, DaskCluster) and dask.scheduler == "local" and dask.workers(5) == 2
