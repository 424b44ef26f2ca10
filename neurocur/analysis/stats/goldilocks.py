"""Engagement against learnability: the Goldilocks curve (Kidd, Piantadosi & Aslin 2012; Oudeyer & Kaplan 2007).

Does a curious agent spend its time where there is something left to learn, neither in
what is trivially easy nor in what cannot be learned? A world of contexts of graded
learnability (``neurocur/experiments_data/goldilocks.toml``) is run with one condition per
dopamine model, and each context's **engagement** (the share of the run's frames spent in
it and the mean dwell per visit, :func:`~neurocur.analysis.stats.dwell.engagement`) is set
against the context's **learnability level** (:func:`neurocur.contexts.learnability.learnability`:
the dense rank of Ω, eq 40, a redrawn source counting as Ω = 1).

- :func:`world_learnability` — the learnability table of a results folder's world (it
  builds the world from the folder's ``config.toml`` to render its frames; it runs no circuit);
- :func:`engagement_by_learnability` — engagement per run and context, with Ω and level;
- :func:`goldilocks_tests` — the two-lines test of an interior peak
  (:func:`~neurocur.analysis.stats.inverted_u.inverted_u_test`, Simonsohn 2018) of each outcome
  over the levels, per condition, runs as covariates (every context of a run is seen by one
  agent). An interior peak needs both slopes significant, so its p-value is the larger of
  the two one-sided ones (an intersection–union test, Berger & Hsu 1996); these are
  Holm-adjusted over the conditions, separately per outcome;
- :func:`~neurocur.analysis.figures.goldilocks.fig_goldilocks` — engagement (mean and 95 % t
  interval over runs) against level, one line per condition.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from neurocur.contexts import build_world
from neurocur.contexts.learnability import learnability
from neurocur.contract import require_columns
from neurocur.results import ResultsStore

from .comparison import adjust_pvalues
from .dwell import engagement
from .inverted_u import inverted_u_test
from .keys import Spec

__all__ = ["OUTCOMES", "world_learnability", "engagement_by_learnability", "goldilocks_tests"]

#: The engagement outcomes, with their axis labels.
OUTCOMES = {"share": "share of frames", "mean_dwell_frames": "mean dwell per visit (frames)"}


def world_learnability(results_dir: str | Path, condition: str | None = None, *, eta: float = 0.05,
                       draws: int = 10, seed: int = 0) -> pd.DataFrame:
    """The learnability table (:func:`~neurocur.contexts.learnability.learnability`) of the world of
    ``condition`` (default: the first) in the results folder's ``config.toml``, its world reset
    with ``seed`` (Ω of a replayed source does not depend on the mixing drawn).

    Parameters
    ----------
    results_dir : str or path
        The results folder; its ``config.toml`` must list the conditions.
    condition : str, optional
        The condition whose world is built; None: the first in ``config.toml``.
    eta : float
        The MCA learning rate η with which Ω (eq 40) is measured.
    draws : int
        Fresh draws of a redrawn source.
    seed : int
        Seed of the world's reset and of the draws.

    Returns
    -------
    pandas.DataFrame
        One row per context: ``context``, ``context_name``, ``source``, ``redrawn``, ``omega``,
        the ``omega_draw_*`` columns, ``pca_dims`` and ``level``.

    Raises
    ------
    ValueError
        When the folder has no conditions, ``condition`` is not one of them, or its world is
        neither synthetic nor episodic (no frames to measure Ω on).
    """
    conditions = (ResultsStore(results_dir).config() or {}).get("conditions", {})
    if not conditions:
        raise ValueError(f"world_learnability: {results_dir} has no config.toml with conditions")
    name = next(iter(conditions)) if condition is None else condition
    if name not in conditions:
        raise ValueError(f"world_learnability: unknown condition {name!r}; have {', '.join(conditions)}")
    world = build_world(conditions[name]["world"])
    try:
        world.reset(seed=seed)
        return learnability(world, eta, draws=draws, seed=seed)
    finally:
        world.close()


def engagement_by_learnability(episodes: pd.DataFrame, levels: pd.DataFrame, spec: Spec = None) -> pd.DataFrame:
    """Engagement per run and context (:func:`~neurocur.analysis.stats.dwell.engagement`) with the
    context's ``omega``, ``redrawn`` and ``level`` from ``levels`` (a learnability table),
    joined on the context index.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table (as ``engagement`` reads it).
    levels : pandas.DataFrame
        A learnability table with ``context``, ``omega``, ``redrawn`` and ``level`` (and the
        ``context_name`` and ``source`` taken when ``spec`` does not give them), as
        ``world_learnability`` returns it.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world, as in ``engagement``.

    Returns
    -------
    pandas.DataFrame
        ``engagement``'s rows with ``omega``, ``redrawn`` and ``level`` added.

    Raises
    ------
    ValueError
        When a column is missing, or ``levels`` has a context more than once.
    """
    require_columns(levels, ["context", "omega", "redrawn", "level"], needed_by="engagement_by_learnability (levels)")
    table = engagement(episodes, spec)
    extra = [c for c in ("context_name", "source") if c not in table]
    return table.merge(levels[["context", *extra, "omega", "redrawn", "level"]], on="context", how="left",
                       validate="many_to_one")


def goldilocks_tests(table: pd.DataFrame, outcomes: Sequence[str] = tuple(OUTCOMES), *,
                     method: str | None = "holm", **kwargs) -> pd.DataFrame:
    """The two-lines test of each outcome over ``level``, one row per (outcome, condition):
    :func:`~neurocur.analysis.stats.inverted_u.inverted_u_test`'s columns, then ``p_value`` (the
    larger one-sided p of the two slopes: the test of an interior peak), ``p_adjusted``
    (``method`` over the conditions of each outcome), ``adjustment`` and ``n_tests``.
    ``kwargs`` go to ``inverted_u_test`` (``alpha``, ``n_boot``, ...).

    Parameters
    ----------
    table : pandas.DataFrame
        One row per (run, context): ``condition``, ``run``, ``level`` and the outcomes, as
        ``engagement_by_learnability`` returns it.
    outcomes : sequence of str
        The outcome columns tested (default: the keys of ``OUTCOMES``).
    method : str or None
        The adjustment over the conditions of each outcome (``"holm"``, ``"bh"`` /
        ``"fdr_bh"``, ``"none"`` or None), as in ``adjust_pvalues``.
    **kwargs
        Keyword arguments of ``inverted_u_test`` (``alpha``, ``paired``, ``n_boot``,
        ``confidence``, ``seed``).

    Returns
    -------
    pandas.DataFrame
        One row per (outcome, condition), outcomes in order.
    """
    require_columns(table, ["condition", "run", "level", *outcomes], needed_by="goldilocks_tests")
    blocks = []
    for outcome in outcomes:
        rows = inverted_u_test(table, "level", outcome, "run", by="condition", **kwargs)
        rows["p_value"] = np.fmax(rows["p1"], rows["p2"]).where(rows[["p1", "p2"]].notna().all(axis=1))
        blocks.append(adjust_pvalues(rows, method))
    return pd.concat(blocks, ignore_index=True)
