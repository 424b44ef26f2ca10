"""Where the agent spends its time: visits, dwell, occupancy over time, and the share of frames
in chosen contexts after an event.

Every function takes the tidy episodes table of :func:`neurocur.analysis.io.load` (one row
per episode, with ``condition`` and ``run``) and returns a tidy DataFrame. The swept keys of
a sweep (:func:`~neurocur.analysis.stats.order.sweep_columns`) are carried as columns.

Definitions:

* **Visit.** A maximal run of consecutive episodes of one run in the same context (the
  agent engaged, episode after episode). Its **dwell** is its number of episodes and of
  frames. The last visit of a run is cut by the run's end (``censored``); it is kept,
  because an agent that settles in a context for good (a noisy TV) shows exactly there.
* **Engagement** with a context (Kidd, Piantadosi & Aslin 2012; Oudeyer & Kaplan 2007):
  the share of the run's frames spent in it, and the mean dwell of its visits.
* **Occupancy** (time-resolved): the share of each bin of ``bin_frames`` global frames
  spent in each context. A frame belongs to the bin of its global step; an episode that
  straddles a bin boundary is split exactly.
* **Share after an event**: the frames spent in a set of contexts after an episode (e.g.
  the episode whose module completed the learnable sources,
  :func:`~neurocur.analysis.stats.efficiency.efficiency_per_run`), over all frames after it.
* **A signal over time** (:func:`signal_over_time`): the mean of a recorded signal (DA, NE) per
  bin of global frames, over the episodes in chosen contexts (DA in a noise context over time).

Contexts are indices in the tables; a ``spec`` (a :class:`~neurocur.contexts.base.SourceSpec`,
or one per condition as :func:`~neurocur.analysis.io.source_specs` returns) names them and
their sources, and lets contexts be given by name (:mod:`~neurocur.analysis.stats.keys`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from neurocur.contract import require_columns

from .bootstrap import BOOTSTRAP_SEED, N_BOOT, bootstrap_ci
from .keys import Spec, context_indices, run_keys, spec_of

__all__ = ["visits", "engagement", "engagement_summary", "occupancy", "signal_over_time", "share_after"]

#: The columns the dwell analyses read (``condition`` and ``run`` are added by the loader).
EPISODE_COLUMNS = ("condition", "run", "episode", "step", "context", "n_frames")


def _sorted(episodes: pd.DataFrame, needed_by: str) -> pd.DataFrame:
    require_columns(episodes, EPISODE_COLUMNS, needed_by=f"{needed_by} (episodes table)")
    return episodes.sort_values(["condition", "run", "episode"], kind="stable").reset_index(drop=True)


def _name_contexts(table: pd.DataFrame, spec: Spec) -> pd.DataFrame:
    """Add ``context_name`` and ``source`` (from ``spec``) after the ``context`` column."""
    if spec is None or table.empty:
        return table
    names, sources = [], []
    for condition, context in zip(table["condition"], table["context"]):
        s = spec_of(spec, condition)
        names.append(s.context_names[context] if 0 <= context < len(s.context_names) else "")
        sources.append(s.context_sources[context] if 0 <= context < len(s.context_sources) else "")
    at = table.columns.get_loc("context") + 1
    table = table.copy()
    table.insert(at, "context_name", names)
    table.insert(at + 1, "source", sources)
    return table


def _all_contexts(episodes: pd.DataFrame, spec: Spec) -> list[int]:
    seen = set(episodes["context"].astype(int))
    if spec is not None:
        for condition in episodes["condition"].unique():
            seen |= set(range(len(spec_of(spec, condition).context_names)))
    return sorted(seen)


def visits(episodes: pd.DataFrame, spec: Spec = None) -> pd.DataFrame:
    """One row per visit (a maximal run of consecutive episodes in one context).

    Columns: condition, run, the swept keys, visit (0-based, per run), context (with
    ``context_name`` and ``source`` when ``spec`` is given), first_episode, step (global
    frame at the visit's start), n_episodes, frames (dwell), censored (the run's last
    visit, cut by the run's end).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, one row per episode, with at least ``condition``, ``run``,
        ``episode``, ``step``, ``context``, ``n_frames``.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name; names the
        contexts (``context_name``, ``source``). None: contexts stay indices.

    Returns
    -------
    pandas.DataFrame
        One row per visit, the columns above, in run and visit order.
    """
    table = _sorted(episodes, "visits")
    keys = run_keys(table)
    if table.empty:
        return pd.DataFrame(columns=[*keys, "visit", "context", "first_episode", "step", "n_episodes", "frames",
                                     "censored"])
    new_run = (table["condition"] != table["condition"].shift()) | (table["run"] != table["run"].shift())
    new_visit = new_run | (table["context"] != table["context"].shift())
    visit_id = new_visit.cumsum()
    grouped = table.groupby(visit_id, sort=False)
    out = grouped[keys + ["context"]].first()
    out["first_episode"] = grouped["episode"].first()
    out["step"] = grouped["step"].first()
    out["n_episodes"] = grouped.size()
    out["frames"] = grouped["n_frames"].sum()
    out = out.reset_index(drop=True)
    out.insert(len(keys), "visit", out.groupby(["condition", "run"]).cumcount())
    out["censored"] = out.groupby(["condition", "run"])["visit"].transform("max") == out["visit"]
    return _name_contexts(out, spec)


def engagement(episodes: pd.DataFrame, spec: Spec = None) -> pd.DataFrame:
    """Engagement per context and run: visits, mean dwell per visit, and share of frames.

    One row per (run, context) for every context of the world (``spec``) or seen in the
    table, also a context the run never visited (n_visits 0, dwell NaN, share 0).
    Columns: condition, run, the swept keys, context (with ``context_name``, ``source``),
    n_visits, mean_dwell_frames, mean_dwell_episodes (per visit, censored last visit
    included; see :func:`visits`), frames (in the context), share (of the run's frames).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, one row per episode, with at least ``condition``, ``run``,
        ``episode``, ``step``, ``context``, ``n_frames``.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name: every one of
        its contexts gets a row, named (``context_name``, ``source``). None: only the contexts
        seen in the table, as indices.

    Returns
    -------
    pandas.DataFrame
        One row per (run, context), the columns above.
    """
    table = visits(episodes, None)
    keys = run_keys(table) if len(table) else run_keys(episodes)
    columns = [*keys, "context", "n_visits", "mean_dwell_frames", "mean_dwell_episodes", "frames", "share"]
    if table.empty:
        return pd.DataFrame(columns=columns)
    stats = table.groupby(["condition", "run", "context"]).agg(
        n_visits=("visit", "size"), mean_dwell_frames=("frames", "mean"),
        mean_dwell_episodes=("n_episodes", "mean"), frames=("frames", "sum"))
    runs = table.groupby(["condition", "run"], sort=True)[keys].first().reset_index(drop=True)
    grid = runs.merge(pd.DataFrame({"context": _all_contexts(episodes, spec)}), how="cross")
    out = grid.join(stats, on=["condition", "run", "context"])
    out["n_visits"] = out["n_visits"].fillna(0).astype(np.int64)
    out["frames"] = out["frames"].fillna(0).astype(np.int64)
    out["share"] = out["frames"] / out.groupby(["condition", "run"])["frames"].transform("sum")
    return _name_contexts(out[columns], spec)


def occupancy(episodes: pd.DataFrame, bin_frames: int = 10_000, spec: Spec = None) -> pd.DataFrame:
    """Time-resolved occupancy: the share of each bin of ``bin_frames`` global frames spent in each context.

    One row per (run, bin, context), every context of the world (``spec``) or seen in the
    table. Columns: condition, run, the swept keys, bin (0-based), step (the bin's first
    frame), context (with ``context_name``, ``source``), frames (of the bin in the
    context), share (frames over the run's frames in the bin; the last bin of a run may be
    partial). Within an episode every frame counts one, so an episode straddling a bin
    boundary is split at it.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, one row per episode, with at least ``condition``, ``run``,
        ``episode``, ``step``, ``context``, ``n_frames``.
    bin_frames : int
        Width of each bin, in global frames; a positive integer.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name: every one of
        its contexts gets a row, named (``context_name``, ``source``). None: only the contexts
        seen in the table, as indices.

    Returns
    -------
    pandas.DataFrame
        One row per (run, bin, context), the columns above.

    Raises
    ------
    ValueError
        When ``bin_frames`` is not a positive integer or a column is missing.
    """
    if int(bin_frames) != bin_frames or bin_frames < 1:
        raise ValueError(f"occupancy: bin_frames must be a positive integer number of frames, got {bin_frames!r}")
    table = _sorted(episodes, "occupancy")
    keys = run_keys(table)
    contexts = _all_contexts(table, spec)
    blocks = []
    for _, run in table.groupby(["condition", "run"], sort=True):
        start = run["step"].to_numpy(dtype=np.int64)
        stop = start + run["n_frames"].to_numpy(dtype=np.int64)
        edges = np.arange(start.min() // bin_frames * bin_frames, stop.max() + bin_frames, bin_frames)
        edges = edges[edges < stop.max()]
        upper = np.minimum(np.append(edges[1:], stop.max()), stop.max())
        context = run["context"].to_numpy()
        frames = np.empty((len(edges), len(contexts)), dtype=np.int64)
        for j, c in enumerate(contexts):
            mine = context == c
            frames[:, j] = _frames_before(start[mine], stop[mine], upper) - _frames_before(start[mine], stop[mine],
                                                                                            edges)
        total = frames.sum(axis=1, keepdims=True)
        block = pd.DataFrame({"bin": np.repeat(np.arange(len(edges)), len(contexts)),
                              "step": np.repeat(edges, len(contexts)),
                              "context": np.tile(contexts, len(edges)),
                              "frames": frames.ravel(),
                              "share": (frames / np.where(total > 0, total, 1)).ravel()})
        for key in reversed(keys):
            block.insert(0, key, run[key].iloc[0])
        blocks.append(block)
    if not blocks:
        return pd.DataFrame(columns=[*keys, "bin", "step", "context", "frames", "share"])
    return _name_contexts(pd.concat(blocks, ignore_index=True), spec)


def _frames_before(start: np.ndarray, stop: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Frames of the episodes ``[start, stop)`` that come before global step ``t`` (each of ``t``)."""
    return np.clip(t[:, None] - start[None, :], 0, (stop - start)[None, :]).sum(axis=1)


def share_after(
    episodes: pd.DataFrame,
    contexts: int | str | Sequence[int | str],
    events: pd.DataFrame | None = None,
    spec: Spec = None,
) -> pd.DataFrame:
    """The share of a run's frames after an event that were spent in ``contexts``.

    ``contexts``: context indices or names (names need ``spec``). ``events``: one row per
    (condition, run) with the column ``episode``: frames of the episodes *after* it count
    (e.g. :func:`~neurocur.analysis.stats.efficiency.efficiency_per_run`'s ``learned_all_episode``,
    renamed ``episode``); a run without a row or with NaN has no event, and its share is
    NaN. ``events=None`` counts the whole run.

    One row per run. Columns: condition, run, the swept keys, event_episode (−1 for the
    whole run), frames_after (all frames after the event), frames_in (those in
    ``contexts``), share (frames_in / frames_after; NaN without an event or without frames
    after it).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, one row per episode, with at least ``condition``, ``run``,
        ``episode``, ``step``, ``context``, ``n_frames``.
    contexts : int, str or sequence of int or str
        The contexts counted: indices, or names of ``spec``'s contexts.
    events : pandas.DataFrame, optional
        One row per (condition, run) with the columns ``condition``, ``run``, ``episode``: the
        event's episode. None: the whole run counts.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name; needed only
        to give ``contexts`` by name.

    Returns
    -------
    pandas.DataFrame
        One row per run, the columns above.

    Raises
    ------
    ValueError
        When a column is missing, a context is unknown, or ``events`` has more than one row for
        a run.
    """
    table = _sorted(episodes, "share_after")
    keys = run_keys(table)
    runs = table.groupby(["condition", "run"], sort=True)[keys].first().reset_index(drop=True)
    if events is None:
        runs["event_episode"] = -1.0
    else:
        require_columns(events, ["condition", "run", "episode"], needed_by="share_after (events table)")
        chosen = events.set_index(["condition", "run"])["episode"].astype(float)
        if chosen.index.duplicated().any():
            raise ValueError("share_after: the events table has more than one row for a (condition, run)")
        runs["event_episode"] = chosen.reindex(pd.MultiIndex.from_frame(runs[["condition", "run"]])).to_numpy()
    wanted = {c: context_indices(contexts, spec_of(spec, c), needed_by="share_after")
              for c in runs["condition"].unique()}
    event = table.merge(runs[["condition", "run", "event_episode"]], on=["condition", "run"],
                        how="left")["event_episode"]
    after = table["episode"].to_numpy() > event.to_numpy()
    inside = np.array([ctx in wanted[c] for c, ctx in zip(table["condition"], table["context"])], dtype=bool)
    frames = table["n_frames"].to_numpy(dtype=np.int64)
    sums = pd.DataFrame({"condition": table["condition"], "run": table["run"],
                         "frames_after": np.where(after, frames, 0),
                         "frames_in": np.where(after & inside, frames, 0)}).groupby(["condition", "run"]).sum()
    out = runs.join(sums, on=["condition", "run"])
    none = out["event_episode"].isna()
    if none.any():
        counts = ["frames_after", "frames_in"]
        out[counts] = out[counts].astype(float)
        out.loc[none, counts] = np.nan
    out["share"] = out["frames_in"] / out["frames_after"].where(out["frames_after"] > 0)
    return out


def engagement_summary(
    episodes: pd.DataFrame, spec: Spec = None, *, n_boot: int = N_BOOT, confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """:func:`engagement` per condition and context, over runs: the mean share of frames and the
    mean dwell per visit, each with its percentile bootstrap interval over runs.

    Columns: condition, context (with ``context_name``, ``source``), n_runs, share, share_ci_low,
    share_ci_high, n_runs_visited (runs that visited the context), dwell_frames (the mean over
    those runs of their mean dwell per visit), dwell_ci_low, dwell_ci_high.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, one row per episode, with at least ``condition``, ``run``,
        ``episode``, ``step``, ``context``, ``n_frames``.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name: every one of
        its contexts gets a row, named (``context_name``, ``source``). None: only the contexts
        seen in the table, as indices.
    n_boot : int
        Number of bootstrap resamples of each interval.
    confidence : float
        Coverage of each interval, in (0, 1).
    seed : int
        Seed of each interval's resamples.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, context), the columns above.
    """
    table = engagement(episodes, spec).drop(columns=["context_name", "source"], errors="ignore")
    rows = []
    for (condition, context), part in table.groupby(["condition", "context"], sort=True):
        share, dwelt = part["share"].to_numpy(float), part["mean_dwell_frames"].dropna().to_numpy(float)
        boot = {"n_boot": n_boot, "confidence": confidence, "seed": seed}
        share_ci, dwell_ci = bootstrap_ci(share, **boot), bootstrap_ci(dwelt, **boot)
        rows.append({"condition": condition, "context": context, "n_runs": len(share), "share": share.mean(),
                     "share_ci_low": share_ci[0], "share_ci_high": share_ci[1], "n_runs_visited": len(dwelt),
                     "dwell_frames": dwelt.mean() if len(dwelt) else np.nan,
                     "dwell_ci_low": dwell_ci[0], "dwell_ci_high": dwell_ci[1]})
    return _name_contexts(pd.DataFrame(rows), spec)


def signal_over_time(
    episodes: pd.DataFrame, column: str, bin_frames: int = 10_000, contexts=None, spec: Spec = None
) -> pd.DataFrame:
    """The per-run mean of ``column`` (e.g. ``da``) per bin of ``bin_frames`` global frames, over the
    episodes in ``contexts`` (indices or names; all by default), e.g. DA in the noise context over time.

    An episode belongs to the bin of its first frame. One row per (run, bin) with such episodes.
    Columns: condition, run, the swept keys, bin, step (the bin's first frame), n_episodes, and
    ``column`` (the mean over the bin's episodes with a value).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, one row per episode, with at least ``condition``, ``run``,
        ``episode``, ``step``, ``context``, ``n_frames`` and ``column``.
    column : str
        The recorded signal averaged (a column of ``episodes``).
    bin_frames : int
        Width of each bin, in global frames; a positive integer.
    contexts : int, str or sequence of int or str, optional
        The contexts whose episodes count: indices, or names of ``spec``'s contexts; None: all.
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name; needed only
        to give ``contexts`` by name.

    Returns
    -------
    pandas.DataFrame
        One row per (run, bin) with episodes in ``contexts``, the columns above.

    Raises
    ------
    ValueError
        When ``bin_frames`` is not a positive integer, a column is missing or a context is
        unknown.
    """
    if int(bin_frames) != bin_frames or bin_frames < 1:
        raise ValueError(f"signal_over_time: bin_frames must be a positive integer number of frames, "
                         f"got {bin_frames!r}")
    table = _sorted(episodes, "signal_over_time")
    require_columns(table, [column], needed_by="signal_over_time (episodes table)")
    keys = run_keys(table)
    if contexts is not None:
        keep = np.zeros(len(table), dtype=bool)
        for condition in table["condition"].unique():
            chosen = context_indices(contexts, spec_of(spec, condition), needed_by="signal_over_time")
            keep |= ((table["condition"] == condition) & table["context"].isin(chosen)).to_numpy()
        table = table[keep]
    table = table.assign(bin=table["step"] // bin_frames).dropna(subset=[column])
    out = table.groupby([*keys, "bin"], sort=True)[column].agg(["size", "mean"]).reset_index()
    out = out.rename(columns={"size": "n_episodes", "mean": column})
    out.insert(len(keys) + 1, "step", out["bin"] * bin_frames)
    return out[[*keys, "bin", "step", "n_episodes", column]]
