"""Executors: what computes an experiment's runs, called by the runner
(:func:`neurocur.experiments.runner.run_experiment`) without knowing which it has.

| executor | module | where the runs are computed |
|---|---|---|
| :class:`~neurocur.experiments.pool.LocalPool` | ``pool`` | worker processes forked from a fork server on this machine (the default) |
| :class:`~neurocur.experiments.cluster.DaskCluster` | ``cluster`` | a Dask cluster: a ``LocalCluster`` (``"local"``) or a scheduler's address |

Each computes run *i* of a condition from the same seed, so the tables are the same for
every executor and every number of workers. Light to import (nothing of the model), so that
the command line can start the local pool's fork server before it imports the model.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Protocol

from .pool import LocalPool

if TYPE_CHECKING:
    from neurocur.results import ResultsStore

    from .conditions import Condition, Experiment

__all__ = ["Executor", "executor_for"]


class Executor(Protocol):
    """Computes (condition, run) pairs and writes each finished run through the results store."""

    def start(self) -> None:
        """Start what can start before the runs are known (the local pool's fork server); a no-op
        when it runs already."""

    def workers(self, runs: int) -> int:
        """The processes that compute ``runs`` runs at once (the memory estimate's count)."""

    def compute(self, exp: Experiment, todo: Iterable[tuple[Condition, int]], store: ResultsStore, bar, ctrl_c, *,
                checkpoint_every: int | None = None, save_agent: bool = False) -> None:
        """Compute the pairs of ``todo`` (sized, generated as they are asked for:
        :class:`~neurocur.experiments.pending.Pending`) and write each through ``store`` as it
        finishes; ``bar`` counts them; ``ctrl_c.count`` is the number of Ctrl-C pressed (once:
        finish what runs, twice: stop at once). ``checkpoint_every``: episodes between two
        checkpoints of a run, where the executor's workers write into the results folder (None:
        :func:`neurocur.results.agents.checkpoint_every`'s default, 0: none); ``save_agent``: write
        each run's trained agent into its run folder."""


def executor_for(scheduler: str | None = None, jobs: int | None = None) -> Executor:
    """The executor of ``--scheduler`` and ``--jobs``: the local pool of ``jobs`` workers
    (default: all cores) without a scheduler, else a Dask cluster: ``"local"`` (a
    ``LocalCluster`` of ``jobs`` workers) or a scheduler's address (``"tcp://HOST:PORT"``).

    Parameters
    ----------
    scheduler : str, optional
        ``--scheduler``: None, ``"local"`` or ``"tcp://HOST:PORT"``.
    jobs : int, optional
        ``--jobs``: the local workers; None: all cores.

    Returns
    -------
    Executor
        A [`LocalPool`][neurocur.experiments.pool.LocalPool] or a
        [`DaskCluster`][neurocur.experiments.cluster.DaskCluster] (nothing started yet).
    """
    if scheduler is None:
        return LocalPool(jobs)
    from .cluster import DaskCluster  # imports dask

    return DaskCluster(scheduler, jobs)
