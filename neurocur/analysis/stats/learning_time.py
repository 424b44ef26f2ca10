"""How long each source took to learn, in epochs (paper sections 4.1.1 and 4.1.4, Figure 4F).

**Learning time.** For a module stored at episode ``e_k``, the frames the agent spent in
the contexts of the module's source during episodes ``e_{k-1} < episode <= e_k``
(``e_{k-1}``: the previous module's storage episode, or the start of the run for the first
module; ``since="start"`` always counts from the start), divided by the epoch length (1000
frames). The adaptive module restarts at every storage, so this is the experience it took
to learn the source. Figure 4F uses the first module of each learnable source.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from neurocur.analysis.results import Results
from neurocur.contract import require_columns

__all__ = ["learning_times", "learning_time_summary"]

#: The columns the learning times read (``condition`` and ``run`` are added by the loader,
#: ``source`` by the world's module report); the modules' ``step`` is copied when present.
EPISODE_COLUMNS = ("condition", "run", "episode", "context", "n_frames")
MODULE_COLUMNS = ("condition", "run", "module", "source", "episode")


def require_learning_columns(episodes: pd.DataFrame, modules: pd.DataFrame, *, needed_by: str) -> None:
    """:func:`neurocur.contract.require_columns` for the columns :func:`learning_times` reads."""
    require_columns(episodes, EPISODE_COLUMNS, needed_by=f"{needed_by} (episodes table)")
    require_columns(modules, MODULE_COLUMNS, needed_by=f"{needed_by} (modules table)")


def learning_times(
    results: Results,
    *,
    since: str = "previous",
    epoch: int = 1000,
) -> pd.DataFrame:
    """Learning time of every stored module, in epochs (Figure 4F).

    ``since="previous"`` counts the frames spent in the contexts of the module's source
    after the previous module's storage episode (exclusive) up to this module's storage
    episode (inclusive); ``since="start"`` counts from the start of the run. Divided by
    ``epoch`` (1000 frames, one pass of a context's local clock).

    Columns: condition, run, module, source, episode, step, epochs, learnable,
    first_of_source (the first module of that source in the run). A module whose source
    drives no context has epochs NaN.

    Parameters
    ----------
    results : Results
        A results folder's tables (:class:`~neurocur.analysis.results.Results`).
    since : str
        ``"previous"`` or ``"start"``: where a module's count of frames begins.
    epoch : int
        The frames of an epoch.

    Returns
    -------
    pandas.DataFrame
        One row per stored module.
    """
    if since not in ("previous", "start"):
        raise ValueError(f"learning_times: since must be 'previous' or 'start', got {since!r}")
    if epoch <= 0:
        raise ValueError(f"learning_times: epoch must be a positive number of frames, got {epoch}")
    episodes, modules = results.episodes, results.modules
    require_learning_columns(episodes, modules, needed_by="learning_times")
    by_run = {key: g for key, g in episodes.groupby(["condition", "run"])}
    rows = []
    for (condition, run), table in modules.groupby(["condition", "run"], sort=True):
        eps = by_run.get((condition, run))
        if eps is None:
            raise ValueError(f"modules of condition {condition!r} run {run} have no episodes")
        ep, ctx, frames = (eps[c].to_numpy() for c in ("episode", "context", "n_frames"))
        previous, seen, spec = -1, set(), results.spec_of(condition)
        for module in table.sort_values("module").itertuples(index=False):
            contexts = spec.contexts_of(module.source)
            lower = previous if since == "previous" else -1
            window = (ep > lower) & (ep <= module.episode) & np.isin(ctx, contexts)
            rows.append({
                "condition": condition, "run": run, "module": module.module,
                "source": module.source, "episode": module.episode,
                "step": getattr(module, "step", math.nan),
                "epochs": frames[window].sum() / epoch if contexts else math.nan,
                "learnable": module.source in spec.learnable,
                "first_of_source": module.source not in seen,
            })
            seen.add(module.source)
            previous = module.episode
    columns = ["condition", "run", "module", "source", "episode", "step", "epochs",
               "learnable", "first_of_source"]
    return pd.DataFrame(rows, columns=columns)


def learning_time_summary(results: Results, *, since: str = "previous") -> pd.DataFrame:
    """Mean ± sd learning time (epochs) per condition and learnable source (Figure 4F).

    Uses the first module of each learnable source in each run. Columns: condition, source,
    n (runs that learned it), mean, sd.

    Parameters
    ----------
    results : Results
        A results folder's tables (:class:`~neurocur.analysis.results.Results`).
    since : str
        As in :func:`learning_times`.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, source).
    """
    require_learning_columns(results.episodes, results.modules, needed_by="learning_time_summary")
    times = learning_times(results, since=since)
    times = times[times["learnable"] & times["first_of_source"]]
    rows = []
    for condition in results.conditions:
        for source in results.spec_of(condition).learnable:
            values = times.loc[(times["condition"] == condition) & (times["source"] == source), "epochs"]
            rows.append({"condition": condition, "source": source, "n": len(values),
                         "mean": values.mean() if len(values) else math.nan,
                         "sd": values.std(ddof=1) if len(values) > 1 else math.nan})
    return pd.DataFrame(rows)
