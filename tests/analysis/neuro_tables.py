"""Small hand-made episodes and modules tables for the dwell, efficiency and event-locked tests, and
:func:`results_of` to hand any two tables to the analysis."""

from __future__ import annotations

import numpy as np
import pandas as pd

from neurocur.analysis import Results
from neurocur.contexts.synthetic import SYNTHETIC


def episodes_of(contexts, frames=100, *, condition="curious", run=0, **columns) -> pd.DataFrame:
    """One run's episodes table: ``contexts`` per episode, ``frames`` (an int or one per episode),
    steps from 0, and any further ``columns`` (one value per episode, or a scalar)."""
    frames = np.broadcast_to(np.asarray(frames, dtype=np.int64), (len(contexts),)).copy()
    return pd.DataFrame({"condition": condition, "run": run, "episode": np.arange(len(frames)),
                         "step": np.concatenate([[0], np.cumsum(frames)[:-1]]),
                         "context": np.asarray(contexts, dtype=np.int64), "n_frames": frames, **columns})


def modules_of(stored, *, condition="curious", run=0) -> pd.DataFrame:
    """One run's modules table from (episode, source) pairs in storage order."""
    return pd.DataFrame({"condition": condition, "run": run, "module": np.arange(len(stored), dtype=np.int64),
                         "episode": np.array([e for e, _ in stored], dtype=np.int64),
                         "source": pd.Series([s for _, s in stored], dtype=object)})


def runs_of(pairs) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Concatenate (episodes, modules) pairs of several runs."""
    pairs = list(pairs)
    return (pd.concat([e for e, _ in pairs], ignore_index=True),
            pd.concat([m for _, m in pairs], ignore_index=True))


def results_of(episodes, modules, spec=SYNTHETIC) -> Results:
    """The tables as a :class:`~neurocur.analysis.results.Results` of the synthetic world (or ``spec``)."""
    return Results.of(episodes, modules, spec)
