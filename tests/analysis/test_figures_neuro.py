"""The figures of the neuromodulator and behaviour analyses draw what their tables say."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from fake_runs import CYCLE, make_run
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure
from neuro_tables import episodes_of, results_of

from neurocur.analysis import (
    efficiency_per_run,
    event_locked_average,
    fig_efficiency,
    fig_event_locked,
    fig_inverted_u,
    fig_occupancy,
    fig_over_time,
    fig_tonic_phasic,
    occupancy,
    order_tables,
    paired_tests,
    signal_over_time,
    tonic_phasic,
)


def test_inverted_u_panels_and_level_means():
    rng = np.random.default_rng(0)
    x = np.repeat(np.arange(7.0), 10)
    table = pd.DataFrame({"level": x, "run": np.tile(np.arange(10), 7), "model": np.where(x >= 0, "a", ""),
                          "perf": -0.3 * (x - 3) ** 2 + rng.normal(0, 0.3, 70)})
    table = pd.concat([table, table.assign(model="b", perf=0.5 * x + rng.normal(0, 0.3, 70))], ignore_index=True)
    fig = fig_inverted_u(table, "level", "perf", by="model")
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    first, second = fig.axes
    assert first.get_title().startswith("a: interior peak") and second.get_title().startswith("b: no interior peak")
    means = first.lines[0]                                       # the errorbar's line of level means
    expected = table[table["model"] == "a"].groupby("level")["perf"].mean()
    assert means.get_ydata() == pytest.approx(expected.to_numpy())


def test_occupancy(tables):
    episodes, _ = tables
    occ = occupancy(episodes, 1000)
    ax = fig_occupancy(occ, [3, 4]).axes[0]
    curious = ax.lines[0]                                        # hue order: curious first
    # CYCLE spends 3 of every 15 episodes in each context: bin 0 (episodes 0-9) has C4 (9-11 → 9) and none of C5
    first = occ[(occ["condition"] == "curious") & (occ["bin"] == 0) & occ["context"].isin([3, 4])]
    assert curious.get_ydata()[0] == pytest.approx(first.groupby("run")["share"].sum().mean()) == 0.1


def test_a_signal_over_time(tables):
    episodes, _ = tables
    table = signal_over_time(episodes, "da", 1000, contexts=[4])
    ax = fig_over_time(table, "da").axes[0]
    expected = table[table["condition"] == "curious"].groupby("step")["da"].mean()
    assert ax.lines[0].get_ydata() == pytest.approx(expected.to_numpy())
    assert ax.get_ylabel() == "da"


def test_event_locked_grid():
    run = episodes_of([0, 0, 1, 1, 1, 2, 0, 0], module_learned=[0, 0, 0, 1, 0, 0, 0, 1],
                      familiar=[0, 1, 1, 0, 1, 1, 0, 0], da=np.arange(8.0), ne_tonic=0.5, ne_phasic=0.2)
    table = event_locked_average(run, window=2)
    fig = fig_event_locked(table)
    assert len(fig.axes) == 3 * 3                                  # da, ne_tonic, ne_phasic × three event kinds
    assert fig.axes[0].get_ylabel() == "da" and fig.axes[0].get_title() == "module stored"
    assert list(fig.axes[0].lines[0].get_ydata()) == [3.0, 4.0, 5.0, 4.0, 5.0]


def test_tonic_phasic_scatter(tables):
    episodes, _ = tables
    fig = fig_tonic_phasic(tonic_phasic(episodes))
    points = [c for c in fig.axes[0].collections if isinstance(c, PathCollection)]
    assert sum(len(c.get_offsets()) for c in points) == 7 * 5            # 7 runs × 5 contexts


def _efficiency_figure(results, a="curious", b="random_switching"):
    return fig_efficiency(efficiency_per_run(results), paired_tests(results, a)["efficiency"], a, b)


def test_efficiency_paired_by_run(tables):
    fig = _efficiency_figure(results_of(*tables))
    left, right = fig.axes
    assert "Wilcoxon signed-rank p = 1\n(paired; Holm, 4 tests; n = 3 pairs)" in left.get_title()
    hollow = [c for c in left.collections if isinstance(c, PathCollection) and len(c.get_offsets())
              and c.get_facecolors().size == 0]
    # pairs 0-2: every curious run learned all (filled), no random-switching run did (hollow, at the horizon)
    assert sum(len(c.get_offsets()) for c in hollow) == 3
    assert all((c.get_offsets()[:, 1] == 6000).all() for c in hollow)
    assert len(left.lines) == 3 + 1                                  # one line per pair, and the horizon


def test_the_efficiency_figure_draws_the_cut_off_its_table_censored_at(tables):
    # every run learned all within 1000 frames: the dashed line is still the cut-off, the shortest run
    results = results_of(*tables)
    table = efficiency_per_run(results).assign(learned_all=True, frames_to_learn_all_censored=1000.0)
    left = fig_efficiency(table, paired_tests(results, "curious")["efficiency"], "curious", "random_switching").axes[0]
    assert left.lines[-1].get_ydata()[0] == table["horizon"].iloc[0] == 6000


def _learns_all_by(episode):
    return [(episode, "S-A", "C1"), (episode + 1, "S-B", "C3"), (episode + 2, "S-C", "C4")]


def test_the_efficiency_figure_and_the_order_table_give_the_same_adjusted_p_values(tmp_path, write_folder):
    # three conditions: the table's efficiency family is 2 comparisons x 4 metrics = 8 tests, and
    # the figure (curious against its control) reads the same family, not a 4-test one of its own
    runs = {"curious": [make_run(CYCLE, _learns_all_by(5 + i), seed=i) for i in range(6)],
            "random_switching": [make_run(CYCLE, [], seed=10 + i) for i in range(6)],
            "slow": [make_run(CYCLE, _learns_all_by(30 + i), seed=20 + i) for i in range(6)]}
    folder = write_folder(tmp_path / "three", runs)
    from neurocur.analysis import Results
    from neurocur.analysis.figures.sets import StandardFigures

    title = StandardFigures().draw(Results.load(folder))["efficiency"].axes[0].get_title()
    table = order_tables(folder)
    row = next(label for label in table.index if label.startswith("frames to learn all") and " vs curious" in label)
    cell = table.loc[row, "random_switching"]
    assert "Holm, 8 tests" in row and "Holm, 8 tests" in title
    # six pairs, all of one sign: Wilcoxon p = 2/2^6 = 0.03125, Holm over 8 tests (the others p = 1): 0.25
    assert cell == "0.25 (n=6)"
    assert "p = 0.25\n" in title
