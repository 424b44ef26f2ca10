"""A sweep's efficiency drawn by condition and sweep point, in the order of the swept values."""

from __future__ import annotations

import numpy as np
import pandas as pd

from neurocur.analysis import Results, efficiency_per_run, fig_sweep_efficiency, sweep_matrix
from neurocur.analysis.figures.sets import StandardFigures
from neurocur.contexts.synthetic import SYNTHETIC


def _sweep(tables, values):
    parts = []
    for table in tables:
        parts.append(pd.concat([table.assign(condition=table["condition"] + f"@LC.gain={v:g}", **{"LC.gain": v})
                                for v in values], ignore_index=True))
    return Results.of(*parts, SYNTHETIC)


def test_the_sweep_matrix_is_each_conditions_mean_by_base_and_point(tables):
    results = _sweep(tables, (2.0, 0.5))
    table = efficiency_per_run(results)
    matrix = sweep_matrix(table.astype({"learned_all": float}), "learned_all")
    assert list(matrix.index) == ["curious", "random_switching"]
    assert list(matrix.columns) == ["LC.gain=0.5", "LC.gain=2"]                 # the swept values' order
    expected = table.groupby("condition")["learned_all"].mean()
    assert matrix.loc["curious", "LC.gain=2"] == expected["curious@LC.gain=2"]
    assert matrix.loc["random_switching", "LC.gain=0.5"] == expected["random_switching@LC.gain=0.5"]
    assert matrix.loc["curious"].tolist() == [0.75, 0.75] and matrix.loc["random_switching"].tolist() == [0.0, 0.0]


def test_a_sweep_gets_its_heatmaps_and_a_folder_without_one_does_not(tables):
    results = _sweep(tables, (0.5, 2.0))
    fig = fig_sweep_efficiency(efficiency_per_run(results))
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert texts == ["0.75", "0.75", "0.00", "0.00"]
    frames = efficiency_per_run(results).groupby("condition")["frames_to_learn_all_censored"].mean()
    assert fig.axes[1].texts[0].get_text() == f"{frames['curious@LC.gain=0.5'] / 1000:.1f}k"
    assert "sweep_efficiency" in StandardFigures().draw(results)
    assert "sweep_efficiency" not in StandardFigures().draw(Results.of(*tables, SYNTHETIC))
    assert np.isfinite(sweep_matrix(efficiency_per_run(results), "n_modules").to_numpy()).all()
