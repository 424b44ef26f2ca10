"""Running an experiment's runs in local worker processes (or on Dask), into a results folder.

This module only schedules: the results store (:class:`neurocur.results.ResultsStore`)
owns the folder (layout, ``config.toml``, fingerprints, resume, lock, atomic writes) and
:func:`~neurocur.experiments.run.run_one` computes a run.

Before any worker starts, while holding the folder's lock: the folder is checked for
resuming (same experiment, same input files, same code); each selected condition's world
is prepared once (:meth:`World.prepare <neurocur.contexts.base.World.prepare>`: an iCub
episode data set is simulated into its cache), and its first episode is run in this
process (:func:`~neurocur.experiments.run.dry_run`), so that a size mismatch fails in
seconds, and the memory of the workers is estimated from it and refused when it exceeds
the memory available (or ``max_memory``).

Runs are always computed in worker processes (``forkserver``, whose server imports this
module once, else ``spawn``), each with single-threaded BLAS, so a seed gives the same
tables for any number of jobs. Runs are submitted one at a time as workers free up.
Workers ignore Ctrl-C and end when this process ends, however it ends. Ctrl-C once:
nothing more is submitted, the runs in progress finish and are written, then
:class:`Interrupted` is raised; twice: the workers are killed at once. Running again into
the same folder skips the finished runs.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import signal
import sys
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

from neurocur.config import path_values
from neurocur.results import ResultsStore
from neurocur.results.lock import describe_holder

from .cluster import compute_on_dask
from .conditions import Condition, Experiment
from .processes import ctrl_c_held, fork_context, note, single_threaded_children, start_fork_server
from .run import dry_run, run_one

__all__ = ["Interrupted", "run_experiment"]

#: a worker's memory before its run: the interpreter with numpy, pandas and numba imported
#: (measured: about 180 MB), added to a dry run's peak for the estimate
WORKER_BASE = 200 * 2**20


class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped :func:`run_experiment`; what happened has been printed to stderr."""


def _worker(condition: Condition, run: int, steps: int, seed: np.random.SeedSequence, out: str) -> tuple[str, int]:
    ResultsStore(out).write_run(run_one(condition, run, steps, seed))
    return condition.name, run


def _init_worker() -> None:
    """In each worker: leave Ctrl-C to the parent, and end when the parent ends."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with, args=(parent,), daemon=True, name="parent-watch").start()


def _exit_with(parent) -> None:
    parent.join()  # returns when the parent process has ended (its sentinel closes)
    os._exit(1)


class _CtrlC:
    """Counts Ctrl-C (SIGINT) during the ``with`` block instead of raising KeyboardInterrupt.

    Only the main thread can catch signals; elsewhere Ctrl-C keeps its default effect.
    """

    def __enter__(self):
        self.count, self._previous = 0, None
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._count)
        return self

    def _count(self, signum, frame) -> None:
        self.count += 1

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)


def _progress_bar(total: int, initial: int, enabled: bool | None):
    from tqdm import tqdm

    disable = not sys.stderr.isatty() if enabled is None else not enabled
    return tqdm(total=total, initial=initial, unit="run", desc="runs", file=sys.stderr, disable=disable,
                dynamic_ncols=True)


def run_experiment(exp: Experiment, out, *, jobs: int | None = None, conditions=None, progress: bool | None = None,
                   max_memory: int | None = None, accept_code_change: bool = False,
                   scheduler: str | None = None) -> Path:
    """Run every (selected condition × run) of ``exp`` into the results folder ``out``.

    ``jobs``: worker processes (default: all cores). ``conditions``: names to run
    (default: all). ``progress``: a tqdm bar of finished runs on stderr; ``None`` shows
    it only when stderr is a terminal. ``max_memory``: bytes the workers may use together
    (default: the memory available). ``accept_code_change``: resume into a folder whose
    runs other code computed. ``scheduler``: None for the local worker pool (default),
    ``"local"`` for a Dask ``LocalCluster`` of ``jobs`` workers, or a Dask scheduler's
    address (``"tcp://HOST:PORT"``); see :mod:`neurocur.experiments.cluster`. The tables
    are the same for every choice. An experiment without a seed takes the folder's (resume)
    or a fresh one. Returns ``out``; :func:`neurocur.analysis.write_summary` then
    aggregates the folder into ``summary.json``.

    Raises ValueError (one line) for every refusal before a worker starts, and
    :class:`Interrupted` after Ctrl-C.
    """
    store = ResultsStore(out)
    selected = exp.select(conditions)
    with store.writing() as lock:
        if lock.stale:
            note(f"cleared the lock of {describe_holder(lock.stale)}, which ended without releasing it")
        if exp.seed is None:
            existing = store.config()
            exp = exp.with_seed(existing["seeds"]["entropy"] if existing else
                                int(np.random.SeedSequence().entropy % 2**63))
        config = exp.resolved()
        inputs = {c.name: path_values(c.world_params) for c in exp.conditions.values() if c.world_params is not None}
        grown = store.check(config, inputs=inputs, accept_code_change=accept_code_change)
        names = [c.name for c in selected]
        done = store.completed(names, exp.runs)
        todo = [(c, i) for c in selected for i in range(exp.runs) if (c.name, i) not in done]
        jobs = max(1, min(jobs or os.cpu_count() or 1, len(todo) or 1))
        if todo and scheduler is None:
            start_fork_server()  # its imports overlap the pre-flight checks
        if todo:
            _preflight(exp, todo, jobs, max_memory)
        store.save_config(grown)
        store.clear_partial()
        bar = _progress_bar(len(names) * exp.runs, len(done), progress)
        try:
            with _CtrlC() as ctrl_c:
                try:
                    if todo and scheduler is not None:
                        compute_on_dask(exp, todo, jobs, store, bar, ctrl_c, scheduler)
                    elif todo:
                        _compute(exp, todo, jobs, str(out), bar, ctrl_c)
                finally:
                    store.clear_partial()
        finally:
            bar.close()
        if ctrl_c.count:
            raise Interrupted()
    return Path(out)


def _preflight(exp: Experiment, todo, jobs: int, max_memory: int | None) -> None:
    """Prepare each world once, run each condition's first episode here, and refuse when the
    workers' estimated memory exceeds ``max_memory`` or the memory available."""
    first = {}
    for c, i in todo:
        first.setdefault(c.name, (c, i))
    for c in {json.dumps(c.world, sort_keys=True): c for c, _ in first.values()}.values():
        c.world_class.prepare(c.world_params)
    peaks = {name: dry_run(c, exp.run_seed(i)) for name, (c, i) in first.items()}
    name, peak = max(peaks.items(), key=lambda item: item[1])
    limit = max_memory if max_memory is not None else available_memory()
    per_worker = WORKER_BASE + peak
    if limit is not None and jobs * per_worker > limit:
        where = "than --max-memory allows" if max_memory is not None else "than this machine has available"
        raise ValueError(f"the runs would need about {_size(jobs * per_worker)} of memory ({jobs} worker"
                         f"{'s' if jobs > 1 else ''} x {_size(per_worker)}, estimated from the first episode of "
                         f"condition {name!r}), more {where} ({_size(limit)}); use fewer --jobs or smaller settings")


def _compute(exp: Experiment, todo, jobs: int, out: str, bar, ctrl_c: _CtrlC) -> None:
    """The pool loop: at most ``jobs`` runs in flight; Ctrl-C once drains them, twice kills them."""
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
                        running[pool.submit(_worker, c, i, exp.steps, exp.run_seed(i), out)] = item
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


def _kill(pool: ProcessPoolExecutor) -> None:
    """End the pool's workers at once (SIGKILL) and wait for them to be gone."""
    workers = list((pool._processes or {}).values())  # no public handle on the workers before Python 3.14
    for process in workers:
        process.kill()
    for process in workers:
        process.join(timeout=10)
    pool.shutdown(wait=True, cancel_futures=True)


def available_memory() -> int | None:
    """Bytes of memory available to new processes: the kernel's MemAvailable, capped by a cgroup
    (container) limit; None when unknown."""
    found = []
    try:
        with open("/proc/meminfo") as fh:
            found += [int(line.split()[1]) * 1024 for line in fh if line.startswith("MemAvailable:")]
    except (OSError, ValueError, IndexError):
        pass
    try:
        cgroup = Path("/sys/fs/cgroup")
        limit = (cgroup / "memory.max").read_text().strip()
        if limit != "max":
            found.append(int(limit) - int((cgroup / "memory.current").read_text()))
    except (OSError, ValueError):
        pass
    if not found:
        try:
            found.append(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (ValueError, OSError, AttributeError):
            return None
    return min(found)


def _size(n: float) -> str:
    return f"{n / 2**30:.1f} GB" if n >= 2**30 else f"{n / 2**20:.0f} MB"
