"""Per-subject work in forked worker processes, with the same results for any number of workers.

A hierarchical fit's E-step (:mod:`neurocur.fit.hierarchical`) finds each subject's MAP under the
same group prior, independently of the other subjects. :class:`SubjectWorkers` maps a task over
the subjects in ``workers`` processes forked from this one, so that the subjects' log-likelihoods
(closures, replays) reach the workers without being pickled; only each call's arguments and
results travel. Each subject's result depends only on its own arguments, never on which worker
computed it or next to which subjects, and the results come back in the subjects' order: a seed
gives the same fit for any number of workers. Workers run BLAS on one thread (many small
matrices: threads would compete with the processes) and leave Ctrl-C to this process. Without
``fork`` (not on Linux or macOS), or with one worker, the task runs here.

The workers are forked, not started from a fork server as ``neurocur run``'s are
(:func:`neurocur.experiments.processes.fork_context`): a fork server's children would need the task
pickled, and a subject's log-likelihood is often a closure (a replay's, a test's lambda) that pickle
refuses. The caller is not single-threaded when it forks (numpy's OpenBLAS starts its own thread on
import), which Python 3.12 and later name in a DeprecationWarning on ``fork`` (3.11, this project's
environment, does not); OpenBLAS stops its thread pool around a fork (its ``pthread_atfork`` handler), and
the workers run BLAS on one thread.
"""

from __future__ import annotations

import multiprocessing
import signal
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from threadpoolctl import threadpool_limits

from ..config import ConfigError

__all__ = ["SubjectWorkers"]

#: the task of the pool being started, inherited by its forked workers
_TASK = None
#: each worker's BLAS limit, kept for the worker's life
_LIMITS = None
#: chunks of subjects per worker and call (a worker that finishes early takes another)
CHUNKS = 4


class SubjectWorkers:
    """``task(i, *shared, item)`` for subject i's ``item``, in ``workers`` forked processes (module docstring);
    a context manager (the processes end with the block).

    Parameters
    ----------
    task : callable
        ``task(i, *shared, item)``: subject i's result, from its index, the arguments every subject shares and
        its own item; inherited by the forked workers, never pickled (only its arguments and results are).
    n_subjects : int
        The subjects; no more workers are started than there are subjects.
    workers : int
        Worker processes (at least 1; 1, or a platform without ``fork``, runs the task in this process).
    """

    def __init__(self, task, n_subjects: int, workers: int = 1):
        if not (isinstance(workers, int | np.integer) and not isinstance(workers, bool) and workers >= 1):
            raise ConfigError("<python>", "workers", "a number of worker processes >= 1", repr(workers))
        self.task, self.pool = task, None
        self.workers = min(int(workers), n_subjects)
        if self.workers > 1 and "fork" not in multiprocessing.get_all_start_methods():
            self.workers = 1

    def __enter__(self) -> SubjectWorkers:
        global _TASK
        if self.workers > 1:
            _TASK = self.task
            try:
                self.pool = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("fork"),
                                                initializer=_start_worker)
                self.pool.submit(int).result()  # fork now, while _TASK is this pool's
            finally:
                _TASK = None
        return self

    def __exit__(self, *exc) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None

    def map(self, shared: tuple, items: list) -> list:
        """``[task(i, *shared, item) for i, item in enumerate(items)]``; an error of a subject is raised here.

        Parameters
        ----------
        shared : tuple
            The arguments every subject's call shares (pickled once per chunk of subjects).
        items : list
            One item per subject, in the subjects' order.

        Returns
        -------
        list
            The subjects' results in their order, the same for any number of workers.
        """
        if self.pool is None:
            return [self.task(i, *shared, item) for i, item in enumerate(items)]
        chunks = [c for c in np.array_split(np.arange(len(items)), self.workers * CHUNKS) if len(c)]
        futures = [self.pool.submit(_run, [int(i) for i in c], shared, [items[i] for i in c]) for c in chunks]
        return [result for future in futures for result in future.result()]


def _start_worker() -> None:
    global _LIMITS
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _LIMITS = threadpool_limits(limits=1, user_api="blas")


def _run(indices: list, shared: tuple, items: list) -> list:
    return [_TASK(i, *shared, item) for i, item in zip(indices, items)]
