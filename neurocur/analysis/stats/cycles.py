"""Learning cycles: the estimation error within each, aligned to module storage (paper Figure 4D),
and how the agent behaved in each (section 4.1.4's exploration and exploitation).

Section 4.1.4: "In each cycle, the error starts high, then trends down as representations
are learned; finally a module is created." Averaged over runs against the global step, the
cycles of different runs fall at different times and the average is flat; aligned to the
storage that ends each cycle, the fall within a cycle shows.

**Cycle.** Cycle k of a run is the episodes after the (k−1)-th module's storing episode up to
and including the k-th's (the first cycle starts with the run). The episodes after the run's
last storage form no cycle (nothing ends them). **Frames before storage** of an episode: the
frames from the end of the episode to the end of the cycle's storing episode (0 for the
storing episode itself). The error is the HPC's context error of the visited context (eq 11
divided by M, column ``error``; any column may be given).

**Behaviour in a cycle** (:func:`cycle_behaviour`). Section 4.1.4: each cycle alternates "mostly
exploration among all contexts, and exploitation once it settles on a context". The adaptive
module learns from the cycle's unfamiliar episodes, whatever their context, so how much of
that input came from the source it ends up storing, and how long the agent stayed with it,
say whether the module was learned while exploring or while engaged.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from neurocur.analysis.results import Results
from neurocur.contexts.base import SourceSpec
from neurocur.contract import require_columns

from .keys import run_keys

__all__ = ["error_cycles", "cycle_behaviour"]


def error_cycles(episodes: pd.DataFrame, column: str = "error", bin_frames: int = 1000, *,
                 context_sources=None) -> pd.DataFrame:
    """The per-run mean of ``column`` in bins of ``bin_frames`` frames before each storage.

    One row per (run, cycle, bin) with a value. Columns: condition, run, the swept keys, cycle
    (1 = ended by the first stored module), bin (0 = the last ``bin_frames`` frames up to the
    storage, 1 the ones before, ...), frames_before (the bin's centre, in frames before
    storage), n_episodes, and ``column`` (the mean over the bin's episodes with a value).

    ``context_sources`` (the source each context shows, by context index:
    :attr:`~neurocur.contexts.base.SourceSpec.context_sources`): the error of the module being
    learned on its own source. Only the episodes whose context shows the source of the cycle's
    storing episode (the source the cycle's module is stored from) are kept, and a ``source``
    column names it (after cycle); the error of the other contexts, which the agent visits
    between, is what makes the mean over all episodes flat.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``episode``, ``step``, ``n_frames``,
        ``module_learned``, ``column`` (and ``context`` when ``context_sources`` is given).
    column : str
        The column averaged (by default the HPC's context error, eq 11 divided by M).
    bin_frames : int
        Width of each bin, in frames; a positive integer.
    context_sources : sequence, optional
        The source each context shows, by context index; None (the default) keeps every episode
        of the cycle.

    Returns
    -------
    pandas.DataFrame
        One row per (run, cycle, bin), the columns above; empty (with those columns) when no run
        stored a module.

    Raises
    ------
    ValueError
        When ``bin_frames`` is not a positive integer or a needed column is missing.
    """
    if int(bin_frames) != bin_frames or bin_frames < 1:
        raise ValueError(f"error_cycles: bin_frames must be a positive integer number of frames, got {bin_frames!r}")
    require_columns(episodes, ["condition", "run", "episode", "step", "n_frames", "module_learned", column,
                               *(["context"] if context_sources is not None else [])],
                    needed_by="error_cycles")
    table = episodes.sort_values(["condition", "run", "episode"], kind="stable").reset_index(drop=True)
    keys = run_keys(table)
    end = (table["step"] + table["n_frames"]).to_numpy()
    stored = table["module_learned"].astype(bool).to_numpy()
    sources = (None if context_sources is None
               else np.asarray(context_sources, dtype=object)[table["context"].to_numpy(dtype=np.int64)])
    by = ["cycle", "source"] if sources is not None else ["cycle"]
    blocks = []
    for _, rows in table.groupby(["condition", "run"], sort=True).indices.items():
        at = rows[stored[rows]]
        if not len(at):
            continue
        # each episode up to the last storage belongs to the cycle of the next storage at or after it
        mine = rows[rows <= at[-1]]
        cycle = np.searchsorted(at, mine)
        before = end[at][cycle] - end[mine]
        block = pd.DataFrame({"row": mine, "cycle": cycle + 1, "bin": before // bin_frames})
        if sources is not None:
            block["source"] = sources[at][cycle]
            block = block[sources[mine] == block["source"].to_numpy()]
        blocks.append(block)
    columns = [*keys, *by, "bin", "frames_before", "n_episodes", column]
    if not blocks:
        return pd.DataFrame(columns=columns)
    cycles = pd.concat(blocks, ignore_index=True)
    cycles = pd.concat([table.loc[cycles["row"], [*keys, column]].reset_index(drop=True),
                        cycles[[*by, "bin"]]], axis=1).dropna(subset=[column])
    out = cycles.groupby([*keys, *by, "bin"], sort=True)[column].agg(["size", "mean"]).reset_index()
    out = out.rename(columns={"size": "n_episodes", "mean": column})
    out["frames_before"] = (out["bin"] + 0.5) * bin_frames
    return out[columns]


def cycle_behaviour(results: Results) -> pd.DataFrame:
    """How the agent behaved in each learning cycle, one row per stored module.

    Over the cycle's unfamiliar episodes (those the adaptive module learned from): the frames
    (``learning_frames``), the frames in contexts of the stored module's source
    (``source_frames``; ``/ 1000`` is its learning time in epochs, as
    :func:`~neurocur.analysis.stats.learning_time.learning_times`), their share (``source_share``), the
    frames of the uninterrupted run of such episodes that ends the cycle (``final_stay``), the
    changes of source between consecutive ones (``source_switches``) and
    ``frames_per_switch`` = learning_frames / (source_switches + 1). Over all the cycle's
    decisions: the share that disengaged (``p_disengage``).

    Columns: condition, run, the swept keys, cycle (1 = ended by the first module), module,
    source, then the numbers above.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables: its episodes (``condition``, ``run``, ``episode``,
        ``context``, ``n_frames``, ``familiar``, ``action``), its modules (``condition``,
        ``run``, ``module``, ``episode``, ``source``), and each condition's world (for the
        source each context shows).

    Returns
    -------
    pandas.DataFrame
        One row per stored module, the columns above; a run that stored none has no row.

    Raises
    ------
    ValueError
        When a needed column is missing.
    """
    episodes, modules = results.episodes, results.modules
    require_columns(episodes, ["condition", "run", "episode", "context", "n_frames", "familiar", "action"],
                    needed_by="cycle_behaviour")
    require_columns(modules, ["condition", "run", "module", "episode", "source"], needed_by="cycle_behaviour")
    table = episodes.sort_values(["condition", "run", "episode"], kind="stable")
    keys = run_keys(table)
    stored = modules.sort_values(["condition", "run", "module"], kind="stable").groupby(["condition", "run"])
    rows = []
    for (condition, run), eps in table.groupby(["condition", "run"], sort=True):
        if (condition, run) not in stored.groups:
            continue
        source_of: SourceSpec = results.spec_of(condition)
        sources = np.asarray(source_of.context_sources, dtype=object)[eps["context"].to_numpy()]
        episode, n_frames = eps["episode"].to_numpy(), eps["n_frames"].to_numpy()
        unfamiliar = ~eps["familiar"].astype(bool).to_numpy()
        disengaged = eps["action"].to_numpy() == "disengage"
        first = eps[keys].iloc[0].to_dict()
        previous = -1
        for k, module in enumerate(stored.get_group((condition, run)).itertuples(index=False)):
            in_cycle = (episode > previous) & (episode <= module.episode)
            learning = in_cycle & unfamiliar
            frames, learned = n_frames[learning], sources[learning]
            mine = learned == module.source
            switches = int(np.count_nonzero(learned[1:] != learned[:-1]))
            others = np.flatnonzero(~mine)
            stay_start = others[-1] + 1 if len(others) else 0  # the final uninterrupted run of the source
            rows.append({**first, "cycle": k + 1, "module": module.module, "source": module.source,
                         "learning_frames": int(frames.sum()), "source_frames": int(frames[mine].sum()),
                         "source_share": frames[mine].sum() / frames.sum() if frames.sum() else np.nan,
                         "final_stay": int(frames[stay_start:].sum()), "source_switches": switches,
                         "frames_per_switch": frames.sum() / (switches + 1),
                         "p_disengage": float(disengaged[in_cycle].mean())})
            previous = module.episode
    columns = [*keys, "cycle", "module", "source", "learning_frames", "source_frames", "source_share", "final_stay",
               "source_switches", "frames_per_switch", "p_disengage"]
    return pd.DataFrame(rows, columns=columns)
