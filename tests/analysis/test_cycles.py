"""The estimation error per learning cycle, aligned to module storage (Figure 4D), by hand."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from neuro_tables import episodes_of

from neurocur.analysis.cycles import error_cycles

# 10 episodes of 100 frames, modules stored at episodes 3 and 7, error = the episode's index
RUN = episodes_of([0, 1] * 5, module_learned=np.isin(np.arange(10), [3, 7]), error=np.arange(10.0))


def test_cycles_are_aligned_to_the_storage_that_ends_them():
    table = error_cycles(RUN, bin_frames=200)
    # cycle 1: episodes 0-3 end 300, 200, 100, 0 frames before the storage at frame 400
    assert table[["cycle", "bin"]].values.tolist() == [[1, 0], [1, 1], [2, 0], [2, 1]]
    assert table["error"].tolist() == [2.5, 0.5, 6.5, 4.5]       # episodes 8 and 9 end no cycle
    assert table["frames_before"].tolist() == [100.0, 300.0, 100.0, 300.0]
    assert table["n_episodes"].tolist() == [2, 2, 2, 2]


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
