"""What the runners share about processes: the workers' environment, the fork server, and lines
to the user. Light to import (no numpy, no neurocur model code), so that the command line can
start the fork server before it imports the model itself."""

from __future__ import annotations

import multiprocessing
import multiprocessing.forkserver
import os
import signal
import sys
from contextlib import contextmanager

__all__ = ["ctrl_c_held", "fork_context", "note", "single_threaded_children", "start_fork_server", "worker_count"]

#: the module the fork server imports once, so that every worker forks with the runner imported
WORKER_MODULE = "neurocur.experiments.runner"
#: imported by the fork server after it: the compiled kernels, loaded once for every worker
WARM_MODULE = "neurocur.experiments.warm"

#: neurocur.learn._compiling.ANNOUNCER (not imported: it imports numba): who says "compiling kernels"
COMPILING_ANNOUNCER = "NEUROCUR_COMPILING_ANNOUNCER"

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


@contextmanager
def single_threaded_children(extra: dict[str, str] | None = None):
    """Processes started in the block (local workers, a Dask LocalCluster's) inherit
    single-threaded BLAS/numba settings, and the variables ``extra``; the environment is restored
    afterwards.

    Parameters
    ----------
    extra : dict of str to str, optional
        Further environment variables for the children.
    """
    values = {**dict.fromkeys(_THREAD_VARS, "1"), **(extra or {})}
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def note(text: str) -> None:
    """One line to the user on stderr, above any progress bar.

    Parameters
    ----------
    text : str
        The line, written after ``neurocur: ``.
    """
    from tqdm import tqdm

    tqdm.write(f"neurocur: {text}", file=sys.stderr)


@contextmanager
def ctrl_c_held():
    """SIGINT blocked in this thread for the ``with`` block: the processes started meanwhile (the
    workers, the fork server) inherit the block and so never see Ctrl-C, and a Ctrl-C pressed
    meanwhile reaches this process when the block ends."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def fork_context():
    """The workers' start method: ``forkserver``, whose server imports :data:`WORKER_MODULE` and
    :data:`WARM_MODULE` once (workers fork from it), else ``spawn``."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([WORKER_MODULE, WARM_MODULE])
    return context


def start_fork_server() -> None:
    """Start the fork server now (with the workers' settings), so that its imports overlap what this
    process does meanwhile; the pool's first worker would otherwise wait for them. A no-op when it
    runs already or the platform has no fork server."""
    if isinstance(fork_context(), multiprocessing.context.ForkServerContext):
        # this process says "compiling kernels" for the server (its own environment is left as it was)
        announcer = {COMPILING_ANNOUNCER: os.environ.get(COMPILING_ANNOUNCER, str(os.getpid()))}
        with single_threaded_children(announcer), ctrl_c_held():
            multiprocessing.forkserver.ensure_running()


def worker_count(jobs: int | None, runs: int) -> int:
    """The workers that compute ``runs`` runs with ``--jobs`` ``jobs`` (default: all cores): never
    more than the runs, at least one.

    Parameters
    ----------
    jobs : int or None
        ``--jobs``; None (or 0): all cores.
    runs : int
        The runs to compute (0 counts as 1).

    Returns
    -------
    int
        The number of workers.
    """
    return max(1, min(jobs or os.cpu_count() or 1, runs or 1))
