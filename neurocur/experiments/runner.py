"""Running an experiment's runs into a results folder: the runner, which calls an executor
(:mod:`neurocur.experiments.executors`: the local pool or a Dask cluster) without knowing which
it has.

The results store (:class:`neurocur.results.ResultsStore`) owns the folder (layout,
``config.toml``, fingerprints, resume, lock, atomic writes), :func:`~neurocur.experiments.run.run_one`
computes a run, and the executor computes the runs. The runner is the one holder of the
folder's lock: it takes it before anything else and keeps it until the runs (and, from the
command line, the summary: ``finish``) are written.

Before any worker starts, while holding the folder's lock: an experiment without a seed gets
one, the folder's when it resumes, else a fresh one (recorded in ``config.toml``); the folder
is checked for resuming (same experiment, same input files, same code); each selected
condition's world is prepared once (:meth:`World.prepare <neurocur.contexts.base.World.prepare>`:
an iCub episode data set is simulated into its cache), and its first episode is run in this
process (:func:`~neurocur.experiments.run.dry_run`), so that a size mismatch fails in
seconds, and the memory of the workers is estimated from it and refused when it exceeds
the memory available (or ``max_memory``).

Ctrl-C once: nothing more is submitted, the runs in progress finish and are written, then
:class:`Interrupted` is raised; twice: they are abandoned. Running again into the same
folder skips the finished runs. The fork server of the local pool imports this module, so
that every worker forks with the model imported.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from neurocur.config import ConfigError, join_key, path_values
from neurocur.results import ResultsStore
from neurocur.results.lock import describe_holder

from .conditions import Experiment
from .executors import Executor, executor_for
from .pending import Pending
from .processes import note
from .run import dry_run

__all__ = ["Interrupted", "run_experiment"]

#: a worker's memory before its run: the interpreter with numpy, pandas and numba imported
#: (measured: about 180 MB), added to a dry run's peak for the estimate
WORKER_BASE = 200 * 2**20


class Interrupted(KeyboardInterrupt):
    """Ctrl-C stopped :func:`run_experiment`; what happened has been printed to stderr."""


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
                   scheduler: str | None = None, executor: Executor | None = None,
                   finish: Callable[[Path], object] | None = None, checkpoint_every: int | None = None,
                   save_agent: bool = False) -> Path:
    """Run every (selected condition × run) of ``exp`` into the results folder ``out``.

    The tables are the same for every executor and number of workers;
    :func:`neurocur.analysis.write_summary` aggregates the folder into ``summary.json``.

    Parameters
    ----------
    exp : Experiment
        The experiment ([`load_experiment`][neurocur.experiments.spec.load_experiment]); one without a
        seed gets the folder's when it resumes, else a fresh one.
    out : path
        The results folder (created when missing; resumed when it holds runs of this experiment).
    jobs : int, optional
        The local workers, or a ``"local"`` Dask cluster's; None: all cores.
    conditions : iterable of str, optional
        The names of the conditions to run; None: all.
    progress : bool, optional
        A tqdm bar of finished runs on stderr; None shows it only when stderr is a terminal.
    max_memory : int, optional
        Bytes the workers may use together; None: the memory available.
    accept_code_change : bool
        Resume into a folder whose runs other code computed.
    scheduler : str, optional
        None for the local worker pool, ``"local"`` for a Dask ``LocalCluster`` of ``jobs``
        workers, or a Dask scheduler's address (``"tcp://HOST:PORT"``)
        (:func:`~neurocur.experiments.executors.executor_for`).
    executor : Executor, optional
        What computes the runs (:mod:`neurocur.experiments.executors`); None: the one of
        ``scheduler`` and ``jobs``.
    finish : callable, optional
        Called with ``out`` after the runs, the folder's lock still held (the command line writes
        the summary).
    checkpoint_every : int, optional
        Episodes between two checkpoints of a run in the local pool (None:
        :func:`neurocur.results.agents.checkpoint_every`'s default, 0: none); a run started again
        continues from its last one.
    save_agent : bool
        Write each run's trained agent into its run folder (``agent/``).

    Returns
    -------
    path
        ``out``.

    Raises
    ------
    ValueError
        One line, for every refusal before a worker starts (a folder that cannot resume, a condition
        that fails its first episode, too little memory).
    Interrupted
        After Ctrl-C, once the finished runs are written.
    """
    executor = executor if executor is not None else executor_for(scheduler, jobs)
    store = ResultsStore(out)
    selected = exp.select(conditions)
    with store.writing() as lock:
        if lock.stale:
            note(f"cleared the lock of {describe_holder(lock.stale)}, which ended without releasing it")
        exp = _seeded(exp, store)
        config = exp.resolved()
        inputs = {c.name: path_values(c.world_params) for c in exp.conditions.values() if c.world_params is not None}
        grown = store.check(config, inputs=inputs, accept_code_change=accept_code_change)
        names = [c.name for c in selected]
        done = store.completed(names, exp.runs)
        todo = Pending(selected, exp.runs, done)
        if todo:
            executor.start()  # the local pool's fork server: its imports overlap the pre-flight checks
            _preflight(exp, todo, executor.workers(len(todo)), max_memory)
        store.save_config(grown)
        store.clear_partial()
        bar = _progress_bar(len(names) * exp.runs, len(done), progress)
        try:
            with _CtrlC() as ctrl_c:
                try:
                    if todo:
                        executor.compute(exp, todo, store, bar, ctrl_c, checkpoint_every=checkpoint_every,
                                         save_agent=save_agent)
                        store.tidy_checkpoints()  # no run in flight any more
                finally:
                    store.clear_partial()
        finally:
            bar.close()
        if ctrl_c.count:
            raise Interrupted()
        if finish is not None:
            finish(Path(out))
    return Path(out)


def _seeded(exp: Experiment, store: ResultsStore) -> Experiment:
    """``exp`` with a seed: its own, else the folder's (a resumed run), else a fresh one; the
    one place an experiment without a seed gets one (recorded in ``config.toml``)."""
    if exp.seed is not None:
        return exp
    existing = store.config()
    return exp.with_seed(existing["seeds"]["entropy"] if existing else int(np.random.SeedSequence().entropy % 2**63))


def _preflight(exp: Experiment, todo: Pending, jobs: int, max_memory: int | None) -> None:
    """Prepare each world once, run each condition's first episode here, and refuse when the
    workers' estimated memory exceeds ``max_memory`` or the memory available."""
    first = todo.first_of_each()
    for c in {json.dumps(c.world, sort_keys=True): c for c, _ in first.values()}.values():
        with _world_errors(exp, c):
            c.world_class.prepare(c.world_params)
    peaks = {}
    for name, (c, i) in first.items():
        with _world_errors(exp, c):
            peaks[name] = dry_run(c, exp.run_seed(i))
    name, peak = max(peaks.items(), key=lambda item: item[1])
    limit = max_memory if max_memory is not None else available_memory()
    per_worker = WORKER_BASE + peak
    if limit is not None and jobs * per_worker > limit:
        where = "than --max-memory allows" if max_memory is not None else "than this machine has available"
        raise ValueError(f"the runs would need about {_size(jobs * per_worker)} of memory ({jobs} worker"
                         f"{'s' if jobs > 1 else ''} x {_size(per_worker)}, estimated from the first episode of "
                         f"condition {name!r}), more {where} ({_size(limit)}); use fewer --jobs or smaller settings")


@contextmanager
def _world_errors(exp: Experiment, condition) -> Iterator[None]:
    """Report a ConfigError of ``condition``'s world parameters that only building the world finds
    (a module of ``world.imports`` that does not import) from the experiment file, as ``world.KEY``."""
    try:
        yield
    except ConfigError as exc:
        if exc.source != type(condition.world_params).__name__:
            raise
        raise ConfigError(exp.path or "<python>", join_key("world", exc.key), exc.expected,
                          f"{exc.got} (condition {condition.name!r})") from None


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
