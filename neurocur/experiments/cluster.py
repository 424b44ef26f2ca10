"""Running an experiment's runs on a Dask cluster (dask.distributed), an executor
(:mod:`neurocur.experiments.executors`).

``run_experiment(..., scheduler="local")`` starts a ``LocalCluster`` of single-threaded
worker processes on loopback; ``scheduler="tcp://HOST:PORT"`` connects to an existing
cluster (docs/cluster.md: SLURM or PBS through dask-jobqueue). Each run is computed by
:func:`~neurocur.experiments.run.run_one` on a worker from the same seed as in the local
pool, and returned to this process (the client), which writes it into the results folder
as soon as it arrives: workers need not see the folder, and a run is never half-written.
A lost worker loses at most the runs it was computing, which Dask computes again
elsewhere; a killed client loses the runs in flight, and running again resumes.

Ctrl-C once cancels what has not finished and stops after writing what has; twice stops
at once. Either way the finished runs are kept.
"""

from __future__ import annotations

import itertools
import logging
from contextlib import ExitStack

from neurocur.config import extra
from neurocur.results import ResultsStore

from .conditions import Experiment
from .probe import probe_scheduler
from .processes import note, single_threaded_children, worker_count
from .run import run_one

__all__ = ["DaskCluster"]

#: the most runs submitted to the cluster at once (more are submitted as these finish)
WINDOW = 1024


class DaskCluster:
    """The cluster of ``scheduler``: ``"local"`` (a ``LocalCluster`` of ``jobs`` single-threaded
    workers, default: all cores) or a scheduler's address, ``"tcp://HOST:PORT"``.

    Parameters
    ----------
    scheduler : str
        ``"local"`` or the scheduler's address (checked when the runs start:
        [`probe_scheduler`][neurocur.experiments.probe.probe_scheduler]).
    jobs : int, optional
        The workers of a ``"local"`` cluster (never more than the runs); None: all cores. A
        scheduler's address brings its own workers.
    """

    def __init__(self, scheduler: str, jobs: int | None = None):
        self.scheduler, self.jobs = scheduler, jobs

    def start(self) -> None:
        """Nothing starts before the runs are known: the cluster is reached (or made) by :meth:`compute`."""

    def workers(self, runs: int) -> int:
        return worker_count(self.jobs, runs)

    def compute(self, exp: Experiment, todo, store: ResultsStore, bar, ctrl_c, *, checkpoint_every: int | None = None,
                save_agent: bool = False) -> None:
        """Compute the (condition, run) pairs of ``todo`` on the cluster and write each finished run
        through ``store``; ``save_agent``: the runs return their trained agents too, written with them.
        ``checkpoint_every`` is the local pool's: a cluster's workers need not see the results folder,
        so a run on the cluster saves no checkpoints."""
        with extra("cluster", "a dask cluster (--scheduler)"):
            import dask
            from distributed import Client, LocalCluster, wait

        with ExitStack() as stack:
            if self.scheduler == "local":
                # Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536 in its workers: glibc then hands memory
                # back to the system after nearly every episode, which made a run 1.5-3.5 times slower
                with single_threaded_children(), dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
                    cluster = stack.enter_context(LocalCluster(
                        n_workers=self.workers(len(todo)), threads_per_worker=1, processes=True, host="127.0.0.1",
                        dashboard_address=None, silence_logs=logging.CRITICAL))
                client = stack.enter_context(Client(cluster))
            else:
                try:
                    probe_scheduler(self.scheduler)
                    client = stack.enter_context(Client(self.scheduler, timeout="20s"))
                except OSError as exc:
                    raise ValueError(f"--scheduler {self.scheduler}: expected a reachable dask.distributed scheduler, "
                                     f"got {exc}") from None
            queue, running = iter(todo), {}

            def top_up() -> None:  # at most WINDOW runs submitted at a time: a huge --runs streams its seeds
                for c, i in itertools.islice(queue, max(0, WINDOW - len(running))):
                    running[client.submit(run_one, c, i, exp.steps, exp.run_seed(i), save_agent=save_agent,
                                          pure=False, key=f"neurocur-{c.name}-run-{i:03d}")] = (c, i)

            top_up()
            announced = False
            while running:
                if ctrl_c.count and not announced:
                    announced = True
                    note("interrupted; finished runs are kept (run again to resume)")
                    client.cancel([f for f in running if f.status != "finished"])
                    running = {f: item for f, item in running.items() if f.status == "finished"}
                if ctrl_c.count >= 2:
                    return
                try:
                    done = wait(list(running), timeout=0.25, return_when="FIRST_COMPLETED").done if running else ()
                except TimeoutError:  # nothing finished within the timeout: look at Ctrl-C again
                    continue
                for future in done:
                    running.pop(future)
                    store.write_run(future.result())
                    bar.update(1)
                if not ctrl_c.count:
                    top_up()

