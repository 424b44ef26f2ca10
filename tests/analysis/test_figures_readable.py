"""The figures say what their tables say, and can be read: one statistic in figure and table,
whole-run count axes, plain symlog ticks, sweeps laid out by their swept values, captioned traces."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis import (
    Results,
    fig_cumulative_error,
    fig_learning_time,
    fig_neuromodulators,
    fig_order_counts,
    fig_reward_function,
    learning_time_summary,
)
from neurocur.analysis.figures.learning import CUMULATIVE_ERROR
from neurocur.contexts.synthetic import SYNTHETIC


def _sweep(tables, values=(0.5, 2.0)):
    """The hand-made folder's two conditions at two points of a sweep of ``LC.gain``."""
    parts = []
    for table in tables:
        copies = []
        for value in values:
            copy = table.copy()
            copy["condition"] = copy["condition"] + f"@LC.gain={value:g}"
            copy["LC.gain"] = value
            copies.append(copy)
        parts.append(pd.concat(copies, ignore_index=True))
    return Results.of(*parts, SYNTHETIC)


def test_the_order_counts_axis_counts_whole_runs(tables):
    episodes, modules = tables
    two = Results.of(episodes[episodes["run"] < 2], modules[modules["run"] < 2], SYNTHETIC)  # n = 2 runs
    for ax in fig_order_counts(two).axes:
        ticks = ax.get_yticks()
        assert len(ticks) >= 2 and np.array_equal(ticks, np.round(ticks))


def test_a_sweeps_order_counts_are_laid_out_by_base_condition_and_swept_value(tables):
    # 2 conditions x 3 points: a 2 x 3 grid (rows: the conditions, columns: the gain, in its order),
    # not six panels in one row
    fig = fig_order_counts(_sweep(tables, values=(2.0, 0.5, 1.0)))
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == 6
    rows = {}
    for ax in axes:
        rows.setdefault(round(ax.get_position().y0, 3), []).append(ax)
    assert len(rows) == 2
    for row in rows.values():
        titles = [ax.get_title() for ax in sorted(row, key=lambda ax: ax.get_position().x0)]
        assert [t.split("@LC.gain=")[1].split(" ")[0] for t in titles] == ["0.5", "1", "2"]
        assert len({t.split("@")[0] for t in titles}) == 1
    width, height = fig.get_size_inches()
    assert width < 2 * height * 3  # about as wide as three panels, not six


def test_without_a_sweep_the_conditions_wrap(tables):
    episodes, modules = tables
    many = [t.assign(condition=t["condition"] + f"_{i}") for i in range(3) for t in (episodes,)]
    mods = [modules.assign(condition=modules["condition"] + f"_{i}") for i in range(3)]
    fig = fig_order_counts(Results.of(pd.concat(many), pd.concat(mods), SYNTHETIC), wrap=4)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 6 and len({round(ax.get_position().y0, 3) for ax in visible}) == 2


def test_the_learning_time_bars_are_the_tables_mean_and_sd(results):
    # the order table prints the learning time as mean ± sd (learning_time_summary): so do the bars
    summary = learning_time_summary(results).dropna(subset=["mean"])
    ax = fig_learning_time(results).axes[0]
    heights = sorted(p.get_height() for p in ax.patches if p.get_height() > 0)
    np.testing.assert_allclose(heights, sorted(summary["mean"]))
    spans = sorted(np.ptp(seg[:, 1]) for c in ax.collections if hasattr(c, "get_segments") for seg in c.get_segments())
    np.testing.assert_allclose(spans, sorted(2 * summary["sd"].dropna()))
    assert "mean ± sd" in ax.get_title()
    # random switching learned S-A and S-B (not S-A first in every run): named once in the legend,
    # then the paper's values (tables in memory of the synthetic world: the paper's experiment)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["curious", "random_switching",
                                                                   "paper (section 4.1.1)"]


def test_a_condition_that_learned_only_a_later_source_is_in_the_legend(tables):
    episodes, modules = tables
    later = modules[~((modules["condition"] == "random_switching") & (modules["source"] == "S-A"))]
    ax = fig_learning_time(Results.of(episodes, later, SYNTHETIC)).axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["curious", "random_switching",
                                                                   "paper (section 4.1.1)"]


def test_symlog_axes_have_plain_ticks(tables):
    episodes, modules = tables
    axes = [fig_neuromodulators(episodes, run=2).axes[0],
            fig_reward_function(Results.of(episodes, modules, SYNTHETIC), run=1).axes[0]]
    for ax in axes:
        assert ax.get_yscale() == "symlog"
        fig = ax.figure
        fig.canvas.draw()
        labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
        assert labels and not any("10^" in t or "$" in t for t in labels)
        values = [float(t.replace("−", "-")) for t in labels]
        assert 0.0 in values and min(values) <= -10
        boxes = sorted((t.get_window_extent() for t in ax.get_yticklabels() if t.get_text()), key=lambda b: b.y0)
        assert all(low.y1 <= high.y0 for low, high in zip(boxes, boxes[1:]))  # no overlapping labels


def test_the_ne_traces_are_captioned_by_the_probes_that_record_them(tables):
    episodes, modules = tables
    config = {"conditions": {"curious": {"resolved_circuit": {"regions": {"LC": {"type": "lc.epsilon_greedy"}}}}}}
    results = Results.of(episodes, modules, SYNTHETIC, config)
    captions = results.probe_docs("curious")
    assert captions["ne_phasic"].startswith("event-locked burst (1 at module storage")
    fig = fig_neuromodulators(episodes, run=2, condition="curious", captions=captions)
    titles = {ax.get_ylabel(): ax.get_title(loc="left") for ax in fig.axes}
    assert titles["NE phasic"] == f"NE phasic: {captions['ne_phasic']}"
    assert titles["NE tonic"].startswith("NE tonic: P(disengage")
    assert fig.axes[2].get_ylim() == pytest.approx((-0.05, 1.05))  # a trace at 1.0 is seen at the top of [0, 1]
    assert results.probe_docs("random_switching") == {}               # no circuit recorded: no caption


def test_the_cumulative_error_figure_says_which_cumulative_error_it_draws(tables):
    fig = fig_cumulative_error(tables[0], run=2)
    assert [ax.get_ylabel() for ax in fig.axes][0] == CUMULATIVE_ERROR
    assert "eq 11" in fig.get_suptitle() and "not a running sum" in fig.get_suptitle()
