"""The estimation error per learning cycle, aligned to module storage (Figure 4D), by hand."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from neuro_tables import episodes_of, modules_of, results_of

from neurocur.analysis.stats.cycles import cycle_behaviour, error_cycles

# 10 episodes of 100 frames, modules stored at episodes 3 and 7, error = the episode's index
RUN = episodes_of([0, 1] * 5, module_learned=np.isin(np.arange(10), [3, 7]), error=np.arange(10.0))


def test_cycles_are_aligned_to_the_storage_that_ends_them():
    table = error_cycles(RUN, bin_frames=200)
    # cycle 1: episodes 0-3 end 300, 200, 100, 0 frames before the storage at frame 400
    assert table[["cycle", "bin"]].values.tolist() == [[1, 0], [1, 1], [2, 0], [2, 1]]
    assert table["error"].tolist() == [2.5, 0.5, 6.5, 4.5]       # episodes 8 and 9 end no cycle
    assert table["frames_before"].tolist() == [100.0, 300.0, 100.0, 300.0]
    assert table["n_episodes"].tolist() == [2, 2, 2, 2]


def test_the_error_of_the_module_being_learned_is_on_its_own_source():
    # contexts alternate 0, 1; both storages (episodes 3 and 7) are in context 1: with context 0
    # showing S-A and context 1 S-B, each cycle keeps its S-B episodes only (1, 3 and 5, 7)
    table = error_cycles(RUN, bin_frames=200, context_sources=("S-A", "S-B"))
    assert table[["cycle", "source", "bin"]].values.tolist() == [[1, "S-B", 0], [1, "S-B", 1],
                                                                  [2, "S-B", 0], [2, "S-B", 1]]
    assert table["error"].tolist() == [3.0, 1.0, 7.0, 5.0]
    assert table["n_episodes"].tolist() == [1, 1, 1, 1]
    # one source for both contexts: every episode is the stored source's, as without sources
    same = error_cycles(RUN, bin_frames=200, context_sources=("S-A", "S-A"))
    assert same["error"].tolist() == error_cycles(RUN, bin_frames=200)["error"].tolist()
    with pytest.raises(ValueError, match="'context'"):
        error_cycles(RUN.drop(columns="context"), context_sources=("S-A", "S-B"))


def test_missing_errors_and_runs_without_storage():
    run = RUN.assign(error=[np.nan, 1, 2, 3, 4, 5, 6, 7, 8, 9])
    other = RUN.assign(run=1, module_learned=False)
    table = error_cycles(pd.concat([run, other], ignore_index=True), bin_frames=200)
    assert table["run"].unique().tolist() == [0]
    first = table[(table["cycle"] == 1) & (table["bin"] == 1)].iloc[0]
    assert first["error"] == 1.0 and first["n_episodes"] == 1
    assert error_cycles(other).empty


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="bin_frames"):
        error_cycles(RUN, bin_frames=0)
    with pytest.raises(ValueError, match="'module_learned'"):
        error_cycles(RUN.drop(columns="module_learned"))


def test_cycle_behaviour_by_hand():
    """Two cycles of a five-context run (C1, C2 show S-A; C3 S-B; ...), counted by hand."""
    contexts = [0, 2, 1, 3, 0, 1, 1, 2, 4, 2, 2]
    actions = ["disengage"] * 5 + ["engage", "disengage", "disengage", "disengage", "engage", "engage"]
    familiar = [False] * 8 + [True, False, False]
    episodes = episodes_of(contexts, [100, 100, 100, 100, 100, 200, 100, 100, 100, 200, 100],
                           familiar=familiar, action=actions)
    modules = modules_of([(6, "S-A"), (10, "S-B")])
    table = cycle_behaviour(results_of(episodes, modules))
    first, second = table.to_dict("records")
    # cycle 1, episodes 0-6: sources A B A C A A A; S-A frames 100+100+100+200+100, switches A|B|A|C|A
    assert (first["cycle"], first["source"], first["learning_frames"], first["source_frames"]) == (1, "S-A", 800, 600)
    assert first["source_share"] == 0.75 and first["final_stay"] == 400 and first["source_switches"] == 4
    assert first["frames_per_switch"] == 160 and first["p_disengage"] == 6 / 7
    # cycle 2, episodes 7-10: episode 8 is familiar (gated), so the learning episodes are B, B, B
    assert (second["learning_frames"], second["source_frames"], second["final_stay"]) == (400, 400, 400)
    assert second["source_switches"] == 0 and second["p_disengage"] == 0.5


def test_cycle_behaviour_skips_runs_without_modules_and_names_missing_columns():
    episodes = episodes_of([0, 1], familiar=False, action="engage")
    assert cycle_behaviour(results_of(episodes, modules_of([]).iloc[:0])).empty
    with pytest.raises(ValueError, match="'familiar'"):
        cycle_behaviour(results_of(episodes.drop(columns="familiar"), modules_of([(1, "S-A")])))
