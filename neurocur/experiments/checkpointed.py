"""A local worker's run: computed with checkpoints (continuing from the last one) and written.

:func:`compute_and_write` is what a worker process of the local pool does for one run
(:mod:`neurocur.experiments.pool`): it computes the run with
:func:`~neurocur.experiments.run.run_one`, saving a checkpoint every
:func:`~neurocur.results.agents.checkpoint_every` episodes into the results folder and
continuing from the last one when the run was stopped before, and writes it through the
results store (which then removes the checkpoint).
"""

from __future__ import annotations

import numpy as np

from neurocur.results import ResultsStore
from neurocur.results.agents import checkpoint_every
from neurocur.results.runinfo import seed_json

from .conditions import Condition
from .run import run_one

__all__ = ["compute_and_write"]


def compute_and_write(condition: Condition, run: int, steps: int, seed: np.random.SeedSequence, out: str, *,
                      every: int | None = None, save_agent: bool = False) -> tuple[str, int]:
    """Compute run ``run`` of ``condition`` and write it into the results folder ``out``.

    Parameters
    ----------
    condition : Condition
        The run's condition.
    run : int
        The run's index.
    steps : int
        The frames of the run.
    seed : numpy.random.SeedSequence
        The run's seed ([`Experiment.run_seed`][neurocur.experiments.conditions.Experiment.run_seed]).
    out : str
        The results folder.
    every : int, optional
        Episodes between two checkpoints (None: :func:`~neurocur.results.agents.checkpoint_every`'s
        default, 0: none); with a nonzero value (or ``save_agent``), a state that cannot be saved is an error at the
        run's start.
    save_agent : bool
        Write the trained agent into the run folder (``agent/``).

    Returns
    -------
    (str, int)
        The condition's name and the run.
    """
    store = ResultsStore(out)
    required = bool(every) or save_agent  # asked for: a state the walker cannot save is an error at once
    every = checkpoint_every(steps, every)
    meta = {"condition": condition.name, "run": int(run), "steps": int(steps), "seed": seed_json(seed)}
    checkpoints = store.checkpoints(condition.name, run, every, meta, required=required) if every or save_agent \
        else None
    store.write_run(run_one(condition, run, steps, seed, checkpoints=checkpoints, save_agent=save_agent))
    return condition.name, run
