"""Statistics of the simulated iCub experiment (paper section 4.2, Figures 6–7).

A results folder of an iCub experiment (``world.type = "icub"``) holds, besides the usual
episodes and modules tables, a ``features.parquet`` per run: every stored module's slow
outputs on the reference episodes of both contexts, with the object's displacement
(written by :meth:`neurocur.contexts.icub.ICubWorld.module_report`). The modules table has the
columns ``quality`` (|corr| of the slowest output y₀ with the object's displacement in the
module's own context), ``arm_corr`` (|corr| of y₀ with the arm's joint state there),
``other_quality`` (with the displacement in the other context) and ``context_corr``
(with the context index over both contexts).

Its figures are :mod:`neurocur.analysis.figures.icub`.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from neurocur.contexts.icub import ICUB
from neurocur.contract import require_columns
from neurocur.learn.correlation import abs_corr
from neurocur.results import ResultsStore

__all__ = ["ICUB", "load_features", "learning_segments", "encoding_table", "arm_invariance"]


def load_features(results_dir: str | Path) -> pd.DataFrame:
    """Every run's ``features.parquet`` as one table (condition, run, module, context, ...).

    Parameters
    ----------
    results_dir : str or path
        The results folder of an iCub experiment.

    Returns
    -------
    pandas.DataFrame
        Every run's features, with ``condition`` and ``run``; empty (with the columns condition,
        run, module, context, episode_index, frame, state, displacement, contact_frame, y0) when
        no run has any.
    """
    return ResultsStore(results_dir).load_table("features", ["condition", "run", "module", "context", "episode_index",
                                                             "frame", "state", "displacement", "contact_frame", "y0"])


def learning_segments(episodes: pd.DataFrame) -> pd.DataFrame:
    """The episodes with ``learning_module`` and ``frames_in`` added.

    ``learning_module`` (0-based) is the adaptive module during the episode: the library
    size before it (``n_modules`` minus the module stored at this episode). ``frames_in``
    counts the frames since that module started learning (its first episode's ``step``).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``step``, ``n_modules`` and
        ``module_learned``.

    Returns
    -------
    pandas.DataFrame
        A copy of ``episodes`` with the two columns added.

    Raises
    ------
    ValueError
        When a column is missing.
    """
    require_columns(episodes, ["condition", "run", "step", "n_modules", "module_learned"],
                    needed_by="learning_segments")
    table = episodes.copy()
    table["learning_module"] = table["n_modules"] - table["module_learned"].astype(int)
    start = table.groupby(["condition", "run", "learning_module"])["step"].transform("min")
    table["frames_in"] = table["step"] - start
    return table


def encoding_table(modules: pd.DataFrame) -> pd.DataFrame:
    """What the slowest output of the first module of each object encodes, per condition.

    Columns: condition, source, n (runs with such a module), and the mean ± sd over those
    modules of ``quality`` (|corr| with the displacement), ``arm_corr``, ``other_quality``
    and ``context_corr`` (see the module docstring).

    Parameters
    ----------
    modules : pandas.DataFrame
        The modules table of an iCub experiment, with ``condition``, ``run``, ``module``,
        ``source`` and the scores above (a score it lacks gives NaN).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, source); each score as ``<score>_mean`` and ``<score>_sd`` (NaN
        for fewer than two modules).
    """
    require_columns(modules, ["condition", "run", "module", "source"], needed_by="encoding_table")
    metrics = ["quality", "arm_corr", "other_quality", "context_corr"]
    first = modules.sort_values("module").drop_duplicates(["condition", "run", "source"])
    rows = []
    for (condition, source), table in first.groupby(["condition", "source"], sort=True):
        row = {"condition": condition, "source": source, "n": len(table)}
        for m in metrics:
            values = table[m].astype(float).dropna() if m in table else pd.Series(dtype=float)
            row[f"{m}_mean"] = values.mean() if len(values) else math.nan
            row[f"{m}_sd"] = values.std(ddof=1) if len(values) > 1 else math.nan
        rows.append(row)
    return pd.DataFrame(rows)


def arm_invariance(features: pd.DataFrame, modules: pd.DataFrame) -> pd.DataFrame:
    """How much of each module's slowest output follows the arm rather than the object.

    The arm and the object are confounded over a whole episode (the hand is past the
    object once it has moved it), so ``arm_corr`` of the modules table mixes the two.
    Here, on the reference episodes of the module's own context (``features``):
    ``corr_displacement`` = |corr(y₀, displacement)| over all frames; ``corr_arm_at_rest``
    = |corr(y₀, arm state)| over the frames before the first contact, when only the arm
    moves; ``rest_sd_ratio`` = sd(y₀) before contact / sd(y₀) over all frames (0: y₀
    ignores the arm, 1: the arm moves y₀ as much as the object does); ``jump`` = |mean
    y₀ from 10 frames after contact on − mean y₀ before contact| / sd(y₀).
    One row per stored module: condition, run, module, source and those four columns.

    Parameters
    ----------
    features : pandas.DataFrame
        The features table (``load_features``).
    modules : pandas.DataFrame
        The modules table, with ``condition``, ``run``, ``module`` and ``source`` (one of the
        iCub's context names).

    Returns
    -------
    pandas.DataFrame
        One row per module of ``features``, the columns above; ``rest_sd_ratio`` and ``jump``
        are NaN when y₀ is constant.

    Raises
    ------
    ValueError
        When a column is missing.
    """
    require_columns(features, ["condition", "run", "module", "context", "frame", "contact_frame", "state",
                               "displacement", "y0"], needed_by="arm_invariance (features table)")
    require_columns(modules, ["condition", "run", "module", "source"], needed_by="arm_invariance (modules table)")
    info = modules.set_index(["condition", "run", "module"])
    rows = []
    for (condition, run, m), table in features.groupby(["condition", "run", "module"], sort=True):
        row = info.loc[(condition, run, m)]
        own = table[table["context"] == ICUB.context_names.index(row["source"])]
        rest = own[own["frame"] < own["contact_frame"]]
        after = own[own["frame"] >= own["contact_frame"] + 10]
        sd = own["y0"].std()
        rows.append({
            "condition": condition, "run": run, "module": m, "source": row["source"],
            "corr_displacement": abs_corr(own["y0"], own["displacement"]),
            "corr_arm_at_rest": abs_corr(rest["y0"], rest["state"]),
            "rest_sd_ratio": rest["y0"].std() / sd if sd > 0 else math.nan,
            "jump": abs(after["y0"].mean() - rest["y0"].mean()) / sd if sd > 0 else math.nan,
        })
    columns = ["condition", "run", "module", "source", "corr_displacement", "corr_arm_at_rest", "rest_sd_ratio", "jump"]
    return pd.DataFrame(rows, columns=columns)
