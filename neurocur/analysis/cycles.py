"""The estimation error within each learning cycle, aligned to module storage (paper Figure 4D).

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
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from neurocur.contract import require_columns

from .dwell import run_keys

__all__ = ["error_cycles"]


def error_cycles(episodes: pd.DataFrame, column: str = "error", bin_frames: int = 1000) -> pd.DataFrame:
    """The per-run mean of ``column`` in bins of ``bin_frames`` frames before each storage.

    One row per (run, cycle, bin) with a value. Columns: condition, run, the swept keys, cycle
    (1 = ended by the first stored module), bin (0 = the last ``bin_frames`` frames up to the
    storage, 1 the ones before, ...), frames_before (the bin's centre, in frames before
    storage), n_episodes, and ``column`` (the mean over the bin's episodes with a value).
    """
    if int(bin_frames) != bin_frames or bin_frames < 1:
        raise ValueError(f"error_cycles: bin_frames must be a positive integer number of frames, got {bin_frames!r}")
    require_columns(episodes, ["condition", "run", "episode", "step", "n_frames", "module_learned", column],
                    needed_by="error_cycles")
    table = episodes.sort_values(["condition", "run", "episode"], kind="stable").reset_index(drop=True)
    keys = run_keys(table)
    end = (table["step"] + table["n_frames"]).to_numpy()
    stored = table["module_learned"].astype(bool).to_numpy()
    blocks = []
    for _, rows in table.groupby(["condition", "run"], sort=True).indices.items():
        at = rows[stored[rows]]
        if not len(at):
            continue
        # each episode up to the last storage belongs to the cycle of the next storage at or after it
        mine = rows[rows <= at[-1]]
        cycle = np.searchsorted(at, mine)
        before = end[at][cycle] - end[mine]
        blocks.append(pd.DataFrame({"row": mine, "cycle": cycle + 1, "bin": before // bin_frames}))
    columns = [*keys, "cycle", "bin", "frames_before", "n_episodes", column]
    if not blocks:
        return pd.DataFrame(columns=columns)
    cycles = pd.concat(blocks, ignore_index=True)
    cycles = pd.concat([table.loc[cycles["row"], [*keys, column]].reset_index(drop=True),
                        cycles[["cycle", "bin"]]], axis=1).dropna(subset=[column])
    out = cycles.groupby([*keys, "cycle", "bin"], sort=True)[column].agg(["size", "mean"]).reset_index()
    out = out.rename(columns={"size": "n_episodes", "mean": column})
    out["frames_before"] = (out["bin"] + 0.5) * bin_frames
    return out[columns]
