"""How efficiently a condition learns the world: frames until every learnable source is learned,
frames spent in the unlearnable contexts, modules per 10⁵ frames (e.g. curious vs random switching).

The module order alone says little about curiosity, since random exposure also orders learning
by learnability (Ω, eq 15); a curious agent should learn the learnable sources *sooner* and
waste fewer frames on the unlearnable ones (paper section 4.3).

Definitions, per run (:func:`efficiency_per_run`):

* **Learned.** A learnable source is learned at its first stored module whose ``source`` is
  it (the world's module report; the rule of ``n_learned`` in
  :func:`~neurocur.analysis.stats.order.per_run`).
* **Frames to learn all**: the frames elapsed from the start of the run to the end of the
  episode that stored the module completing the learnable sources; NaN when the run ended
  first (``learned_all`` false: the time is right-censored at the run length).
* **Censored rule.** ``frames_to_learn_all_censored`` is min(frames to learn all, T), and T
  when not all were learned, where the horizon T is the shortest run of the conditions compared
  (:func:`censoring_horizon`; a run ends at the first visit boundary past the requested frames,
  so runs differ by less than a visit). Every run is censored at the same T, in every table and
  figure that compares them (the order table names it), so the sign of each paired difference is
  right (a run that learned all beats its twin that did not) and two censored twins tie
  (difference 0, dropped by the Wilcoxon signed-rank test: the paired form of Gehan's 1965
  generalised Wilcoxon test). The magnitude of a difference with a censored twin is a lower
  bound, so the test and the difference are conservative. The mean of the censored values
  is the restricted mean time to learn all up to T (Royston & Parmar 2013). Whether all
  were learned is compared separately, by McNemar's exact test on the paired yes/no outcomes.
* **Frames unlearnable**: frames spent in the contexts of unlearnable sources (S-D in the
  synthetic world), and their share of the run.
* **Modules per 10⁵ frames**: stored modules (any source) per 10⁵ frames of the run.

:func:`compare_efficiency` tests two conditions paired by run
(:func:`~neurocur.analysis.stats.comparison.compare`: Wilcoxon signed-rank, McNemar exact,
percentile bootstrap intervals over the pairs, Holm across the metrics).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from neurocur.analysis.results import Results
from neurocur.contexts.base import SourceSpec
from neurocur.contract import require_columns

from .bootstrap import BOOTSTRAP_SEED, N_BOOT, bootstrap_ci
from .comparison import compare
from .keys import run_keys
from .order import clopper_pearson

__all__ = ["EFFICIENCY_TESTS", "censoring_horizon", "efficiency_per_run", "efficiency_summary", "compare_efficiency"]

#: The per-run metrics of :func:`efficiency_per_run` that :func:`compare_efficiency` tests, in order.
EFFICIENCY_TESTS = ("frames_to_learn_all_censored", "learned_all", "frames_unlearnable", "modules_per_1e5")
#: What each metric of :func:`efficiency_summary` is, in words.
EFFICIENCY_LABELS = {
    "learned_all": "all learnable sources learned",
    "frames_to_learn_all": "frames to learn all (runs that did)",
    "frames_to_learn_all_censored": "frames to learn all (censored at the run length)",
    "frames_unlearnable": "frames in unlearnable contexts",
    "modules_per_1e5": "modules per 10⁵ frames",
}

EPISODE_COLUMNS = ("condition", "run", "episode", "context", "n_frames")
MODULE_COLUMNS = ("condition", "run", "module", "source", "episode")


def require_efficiency_columns(episodes: pd.DataFrame, modules: pd.DataFrame, *, needed_by: str) -> None:
    """:func:`neurocur.contract.require_columns` for the columns :func:`efficiency_per_run` reads."""
    require_columns(episodes, EPISODE_COLUMNS, needed_by=f"{needed_by} (episodes table)")
    require_columns(modules, MODULE_COLUMNS, needed_by=f"{needed_by} (modules table)")


def _run_row(eps: pd.DataFrame, mods: pd.DataFrame | None, spec: SourceSpec) -> dict:
    eps = eps.sort_values("episode")
    frames = eps["n_frames"].to_numpy(dtype=np.int64)
    elapsed = pd.Series(np.cumsum(frames), index=eps["episode"].to_numpy())
    n_steps = int(frames.sum())
    stored = [] if mods is None else list(mods.sort_values("module")[["source", "episode"]].itertuples(index=False))
    first = {}
    for source, episode in stored:
        if source in spec.learnable and source not in first:
            first[source] = int(episode)
    learned_all = len(first) == len(spec.learnable) and len(spec.learnable) > 0
    episode = max(first.values()) if learned_all else math.nan
    to_learn = float(elapsed.loc[episode]) if learned_all else math.nan
    unlearnable = [i for i, s in enumerate(spec.context_sources) if s in spec.unlearnable]
    in_unlearnable = int(frames[np.isin(eps["context"].to_numpy(), unlearnable)].sum())
    return {"n_steps": n_steps, "n_learned": len(first), "learned_all": learned_all,
            "learned_all_episode": float(episode), "frames_to_learn_all": to_learn,
            "frames_unlearnable": in_unlearnable,
            "share_unlearnable": in_unlearnable / n_steps if n_steps else math.nan,
            "n_modules": len(stored), "modules_per_1e5": len(stored) / n_steps * 1e5 if n_steps else math.nan}


def censoring_horizon(results: Results) -> float:
    """The frames of the shortest run of ``results``: the common cut-off T of the censored times.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables; its episodes table's ``n_frames`` are summed per run.

    Returns
    -------
    float
        The shortest run's frames; NaN when there are no runs.
    """
    frames = results.episodes.groupby(["condition", "run"])["n_frames"].sum()
    return float(frames.min()) if len(frames) else math.nan


def efficiency_per_run(results: Results, *, horizon: float | None = None) -> pd.DataFrame:
    """One row per (condition, run): how efficiently the run learned (see the module docstring).

    ``horizon``: the cut-off T of ``frames_to_learn_all_censored`` (default: the shortest run of
    ``results``, :func:`censoring_horizon`; never past it: a shorter run cannot say whether it
    would have learned all by then); it is the ``horizon`` column.

    Every run of the episodes table has a row. Columns: condition, run, the swept keys of a
    sweep, n_steps (frames), n_learned (learnable sources learned), learned_all (bool),
    learned_all_episode (the storing episode; NaN), frames_to_learn_all (NaN when not all),
    frames_to_learn_all_censored (censored at ``horizon``), frames_unlearnable,
    share_unlearnable, n_modules, modules_per_1e5, horizon.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables: its episodes (``condition``, ``run``, ``episode``,
        ``context``, ``n_frames``), its modules (``condition``, ``run``, ``module``, ``source``,
        ``episode``), and each condition's world (which sources are learnable).
    horizon : float, optional
        The cut-off T, in frames; at most the shortest run. None: the shortest run.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run), the columns above.

    Raises
    ------
    ValueError
        When a column is missing or ``horizon`` is past the shortest run.
    """
    episodes, modules = results.episodes, results.modules
    require_efficiency_columns(episodes, modules, needed_by="efficiency_per_run")
    keys = run_keys(episodes)
    by_run = {key: g for key, g in modules.groupby(["condition", "run"])}
    rows = []
    for (condition, run), eps in episodes.groupby(["condition", "run"], sort=True):
        row = {k: eps[k].iloc[0] for k in keys}
        rows.append({**row, **_run_row(eps, by_run.get((condition, run)), results.spec_of(condition))})
    columns = [*keys, "n_steps", "n_learned", "learned_all", "learned_all_episode", "frames_to_learn_all",
               "frames_to_learn_all_censored", "frames_unlearnable", "share_unlearnable", "n_modules",
               "modules_per_1e5", "horizon"]
    table = pd.DataFrame(rows, columns=[c for c in columns if c not in ("frames_to_learn_all_censored", "horizon")])
    shortest = float(table["n_steps"].min()) if len(table) else math.nan
    if horizon is None:
        horizon = shortest
    elif not horizon <= shortest:
        raise ValueError(f"efficiency_per_run: the horizon {horizon:g} is past the shortest run ({shortest:g} frames)")
    table["frames_to_learn_all_censored"] = table["frames_to_learn_all"].clip(upper=horizon).fillna(horizon)
    table["horizon"] = float(horizon)
    return table[columns].astype({"learned_all": bool})


def efficiency_summary(
    table: pd.DataFrame,
    *,
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """Per condition and metric: runs, mean with its interval, median, range.

    ``table``: an :func:`efficiency_per_run` table.
    Metrics (:data:`EFFICIENCY_LABELS`): learned_all (a proportion, Clopper–Pearson interval),
    frames_to_learn_all (over the runs that learned all), frames_to_learn_all_censored
    (every run; its mean is the restricted mean), frames_unlearnable, modules_per_1e5 (percentile
    bootstrap interval of the mean over runs). Columns: condition, metric, label, n (runs with
    a value), mean, ci_low, ci_high, median, min, max.

    Parameters
    ----------
    table : pandas.DataFrame
        An ``efficiency_per_run`` table.
    n_boot : int
        Number of bootstrap resamples of each interval.
    confidence : float
        Coverage of each interval, in (0, 1) (``learned_all``'s Clopper–Pearson interval too).
    seed : int
        Seed of each interval's resamples.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, metric), the columns above.
    """
    require_columns(table, ["condition", "run", *EFFICIENCY_LABELS], needed_by="efficiency_summary")
    rows = []
    for condition, runs in table.groupby("condition", sort=True):
        for metric, label in EFFICIENCY_LABELS.items():
            values = runs[metric].astype(float).dropna().to_numpy()
            if metric == "learned_all":
                low, high = clopper_pearson(int(values.sum()), len(values), confidence)
            else:
                low, high = bootstrap_ci(values, n_boot=n_boot, confidence=confidence, seed=seed)
            some = len(values) > 0
            rows.append({"condition": condition, "metric": metric, "label": label, "n": len(values),
                         "mean": values.mean() if some else math.nan, "ci_low": low, "ci_high": high,
                         "median": float(np.median(values)) if some else math.nan,
                         "min": values.min() if some else math.nan, "max": values.max() if some else math.nan})
    return pd.DataFrame(rows)


def compare_efficiency(
    table: pd.DataFrame,
    a: str,
    b: str,
    *,
    adjust: str | None = "holm",
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """Condition ``a`` against ``b`` on :data:`EFFICIENCY_TESTS`, paired by run.

    :func:`~neurocur.analysis.stats.comparison.compare` on the :func:`efficiency_per_run` ``table``: the frames
    to learn all censored at the run length, the frames in unlearnable contexts and the
    modules per 10⁵ frames by the Wilcoxon signed-rank test (Wilcoxon 1945), learned-all by
    McNemar's exact test (McNemar 1947), each with percentile bootstrap intervals over the
    pairs and Holm's adjustment (Holm 1979) over the four (``adjust``). Columns:
    :data:`~neurocur.analysis.stats.comparison.COMPARE_COLUMNS`; ``difference`` < 0 in frames means
    ``a`` learned sooner.

    Parameters
    ----------
    table : pandas.DataFrame
        An ``efficiency_per_run`` table.
    a, b : str
        The conditions compared.
    adjust : str or None
        The multiple-comparison adjustment over the four metrics (``"holm"``, ``"bh"`` /
        ``"fdr_bh"``, ``"none"`` or None), as in ``compare``.
    n_boot : int
        Number of bootstrap resamples of each interval.
    confidence : float
        Coverage of each interval, in (0, 1).
    seed : int
        Seed of each interval's resamples.

    Returns
    -------
    pandas.DataFrame
        One row per metric of ``EFFICIENCY_TESTS``.
    """
    require_columns(table, ["condition", "run", *EFFICIENCY_TESTS], needed_by="compare_efficiency")
    return compare(table, a, b, list(EFFICIENCY_TESTS), paired=True, adjust=adjust, n_boot=n_boot,
                   confidence=confidence, seed=seed)
