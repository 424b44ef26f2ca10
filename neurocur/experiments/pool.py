"""The local worker pool, an executor (:mod:`neurocur.experiments.executors`): runs computed in
worker processes on this machine.

Workers are forked from a fork server (``forkserver``, whose server imports the runner and
the compiled kernels once, :mod:`.processes`; else ``spawn``), each with single-threaded BLAS,
so a seed gives the same tables for any number of jobs. :meth:`LocalPool.start` is the one
place that starts the fork server: the command line calls it first, so that the server's
imports overlap its own. Runs are submitted one at a time as workers free up; each worker
writes its run into the results folder. Workers ignore Ctrl-C and end when this process
ends, however it ends. Ctrl-C once: nothing more is submitted and the runs in progress
finish; twice: the workers are killed at once.

Light to import (the model is imported by the workers' fork server, not here).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from .processes import ctrl_c_held, fork_context, note, single_threaded_children, start_fork_server, worker_count

__all__ = ["LocalPool"]


class LocalPool:
    """``jobs`` worker processes on this machine (default: all cores).

    Parameters
    ----------
    jobs : int, optional
        The worker processes (never more than the runs, at least one); None: all cores.
    """

    def __init__(self, jobs: int | None = None):
        self.jobs = jobs

    def start(self) -> None:
        start_fork_server()

    def workers(self, runs: int) -> int:
        return worker_count(self.jobs, runs)

    def compute(self, exp, todo, store, bar, ctrl_c, *, checkpoint_every: int | None = None,
                save_agent: bool = False) -> None:
        """The pool loop: at most :meth:`workers` runs in flight; Ctrl-C once drains them, twice kills them.
        Each worker saves a checkpoint of its run every ``checkpoint_every`` episodes and continues from
        the last one (:func:`~neurocur.experiments.checkpointed.compute_and_write`)."""
        jobs = self.workers(len(todo))
        out = str(store.root)
        queue = iter(todo)
        running: dict = {}
        error: Exception | None = None
        announced = False
        with single_threaded_children():
            pool = ProcessPoolExecutor(max_workers=jobs, mp_context=fork_context(), initializer=_init_worker)
            try:
                while True:
                    while not ctrl_c.count and error is None and len(running) < jobs:
                        item = next(queue, None)
                        if item is None:
                            break
                        c, i = item
                        with ctrl_c_held():  # submit() starts the worker processes
                            running[pool.submit(_worker, c, i, exp.steps, exp.run_seed(i), out, every=checkpoint_every,
                                                         save_agent=save_agent)] = item
                    if ctrl_c.count and not announced:
                        announced = True
                        note(f"interrupted; finishing the {len(running)} run(s) in progress, then stopping "
                             "(Ctrl-C again to abandon them); finished runs are kept (run again to resume)"
                             if running else "interrupted; finished runs are kept (run again to resume)")
                    if ctrl_c.count >= 2 and running:
                        note(f"abandoned the {len(running)} run(s) in progress")
                        _kill(pool)
                        return
                    if not running:
                        break
                    finished, _ = wait(running, timeout=0.25, return_when=FIRST_COMPLETED)
                    for future in finished:
                        running.pop(future)
                        try:
                            future.result()
                            bar.update(1)
                        except BrokenProcessPool:
                            error = error or ChildProcessError(
                                "a worker process ended abruptly (killed by the system, e.g. for lack of memory?); "
                                "finished runs are kept (run again to resume)")
                        except Exception as exc:  # the others in flight finish; then the first error is raised
                            error = error or exc
            except BaseException:
                _kill(pool)
                raise
            pool.shutdown(wait=True)
        if error is not None:
            raise error


def _worker(condition, run: int, steps: int, seed, out: str, **options) -> tuple[str, int]:
    """In a worker: compute one run with its checkpoints and write it (the fork server has imported
    the model already)."""
    from .checkpointed import compute_and_write

    return compute_and_write(condition, run, steps, seed, out, **options)


def _init_worker() -> None:
    """In each worker: leave Ctrl-C to the parent, and end when the parent ends."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with, args=(parent,), daemon=True, name="parent-watch").start()


def _exit_with(parent) -> None:
    parent.join()  # returns when the parent process has ended (its sentinel closes)
    os._exit(1)


def _kill(pool: ProcessPoolExecutor) -> None:
    """End the pool's workers at once (SIGKILL) and wait for them to be gone."""
    workers = list((pool._processes or {}).values())  # no public handle on the workers before Python 3.14
    for process in workers:
        process.kill()
    for process in workers:
        process.join(timeout=10)
    pool.shutdown(wait=True, cancel_futures=True)
