"""Running an experiment's runs in local worker processes, into a results folder.

This module only schedules: the results store (:class:`neurocur.results.ResultsStore`)
owns the folder (layout, ``config.toml``, resume, atomic writes) and
:func:`~neurocur.experiments.run.run_one` computes a run.

Before the workers start, each selected condition's world is prepared once
(:meth:`World.prepare <neurocur.contexts.base.World.prepare>`: an iCub episode
data set is simulated into its cache), so that workers only read it.

Runs are always computed in worker processes (``forkserver``, else ``spawn``), each with
single-threaded BLAS, so a seed gives the same tables for any number of jobs. Running
again into the same folder skips the finished runs; an interrupted sweep resumes where
it stopped.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import sys
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from neurocur.results import ResultsStore

from .run import run_one
from .spec import Condition, Experiment

__all__ = ["run_experiment"]

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


def _worker(condition: Condition, run: int, steps: int, seed: np.random.SeedSequence, out: str) -> tuple[str, int]:
    ResultsStore(out).write_run(run_one(condition, run, steps, seed))
    return condition.name, run


@contextmanager
def _single_threaded_children():
    """Worker processes inherit single-threaded BLAS/numba settings (restored afterwards)."""
    saved = {k: os.environ.get(k) for k in _THREAD_VARS}
    os.environ.update({k: "1" for k in _THREAD_VARS})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _mp_context():
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _progress_bar(total: int, initial: int, enabled: bool | None):
    from tqdm import tqdm

    disable = not sys.stderr.isatty() if enabled is None else not enabled
    return tqdm(total=total, initial=initial, unit="run", desc="runs", file=sys.stderr, disable=disable,
                dynamic_ncols=True)


def run_experiment(exp: Experiment, out, *, jobs: int | None = None, conditions=None,
                   progress: bool | None = None) -> Path:
    """Run every (selected condition × run) of ``exp`` into the results folder ``out``.

    ``jobs``: worker processes (default: all cores). ``conditions``: names to run
    (default: all). ``progress``: a tqdm bar of finished runs on stderr; ``None`` shows
    it only when stderr is a terminal. An experiment without a seed takes the folder's
    (resume) or a fresh one. Returns ``out``; :func:`neurocur.analysis.write_summary`
    then aggregates the folder into ``summary.json``.
    """
    store = ResultsStore(out)
    selected = exp.select(conditions)
    if exp.seed is None:
        existing = store.config()
        exp = exp.with_seed(existing["seeds"]["entropy"] if existing else
                            int(np.random.SeedSequence().entropy % 2**63))
    store.open(exp.resolved())
    store.clear_partial()
    names = [c.name for c in selected]
    done = store.completed(names, exp.runs)
    todo = [(c, i) for c in selected for i in range(exp.runs) if (c.name, i) not in done]
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(todo) or 1))
    bar = _progress_bar(len(names) * exp.runs, len(done), progress)
    try:
        if todo:
            for c in {json.dumps(c.world, sort_keys=True): c for c, _ in todo}.values():
                c.world_class.prepare(c.world_params)
            with _single_threaded_children(), ProcessPoolExecutor(max_workers=jobs, mp_context=_mp_context()) as pool:
                pending = {pool.submit(_worker, c, i, exp.steps, exp.run_seed(i), str(out)) for c, i in todo}
                try:
                    while pending:
                        finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                        for future in finished:
                            future.result()
                            bar.update(1)
                except BaseException:
                    for future in pending:
                        future.cancel()
                    raise
    finally:
        bar.close()
        store.clear_partial()
    return Path(out)
