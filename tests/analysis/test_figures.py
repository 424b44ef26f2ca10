"""Every figure function returns a Figure with the expected axes and lines."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from neurocur.analysis import (
    fig_cumulative_error,
    fig_intrinsic_reward,
    fig_learning_time,
    fig_neuromodulators,
    fig_order_counts,
    fig_reward_function,
    write_all,
)
from neurocur.analysis.figures import EVENT_GID, _reward_estimates


def _data_lines(ax):
    return [line for line in ax.lines if line.get_gid() != EVENT_GID]


def test_cumulative_error(tables):
    episodes, _ = tables
    fig = fig_cumulative_error(episodes, run=2)
    assert isinstance(fig, Figure) and len(fig.axes) == 1
    ax = fig.axes[0]
    assert len(ax.lines) == 2
    mean, single = ax.lines
    # the mean is binned per 1000 steps (6000 steps -> 6 bins); the single run per episode
    assert len(mean.get_xdata()) == 6 and len(single.get_xdata()) == 60
    expected = episodes[episodes["condition"] == "curious"].assign(b=lambda t: t["step"] // 1000)
    first_bin = expected[expected["b"] == 0].groupby("run")["error"].mean().mean()
    assert mean.get_ydata()[0] == pytest.approx(first_bin)
    assert "run 2" in single.get_label()


def test_intrinsic_reward(tables):
    episodes, _ = tables
    fig = fig_intrinsic_reward(episodes, "random_switching", window=1, ylim=(-60, 5))
    ax = fig.axes[0]
    assert len(fig.axes) == 1 and len(ax.lines) == 2  # the reward and the zero line
    table = episodes[episodes["condition"] == "random_switching"]
    last = table[table["step"] >= 5000].groupby("run")["da"].mean().mean()
    assert ax.lines[0].get_ydata()[-1] == pytest.approx(last)
    assert ax.get_ylim() == (-60, 5) and "clipped" in ax.get_title()
    no_boredom = fig_intrinsic_reward(episodes, include_boredom=False).axes[0].lines[0].get_ydata()
    assert no_boredom.min() > -1.0


def test_learning_time(tables):
    fig = fig_learning_time(*tables)
    ax = fig.axes[0]
    assert len(fig.axes) == 1
    bars = [p for p in ax.patches if p.get_height() > 0]
    # curious learned S-A, S-B, S-C; random_switching learned S-A and S-B
    assert len(bars) == 5
    only = fig_learning_time(*tables, condition="curious").axes[0]
    assert len([p for p in only.patches if p.get_height() > 0]) == 3


def test_reward_function(tables):
    episodes, _ = tables
    fig = fig_reward_function(episodes, run=1, alpha=None)
    ax = fig.axes[0]
    assert len(fig.axes) == 1 and len(ax.lines) == 5
    run = episodes[(episodes["condition"] == "curious") & (episodes["run"] == 1)]
    for c, line in enumerate(ax.lines):
        # sample average of the context's rewards, at the end of the run
        assert line.get_ydata()[-1] == pytest.approx(run.loc[run["context"] == c, "da"].mean())
    assert ax.lines[2].get_label() == "C3 (S-B)"
    ema = fig_reward_function(episodes, run=1, alpha=1.0).axes[0].lines[4].get_ydata()
    assert ema[-1] == pytest.approx(run.loc[run["context"] == 4, "da"].iloc[-1])


def test_order_counts(tables):
    episodes, modules = tables
    fig = fig_order_counts(modules, episodes)
    assert len(fig.axes) == 2
    heights = sorted(p.get_height() for p in fig.axes[0].patches if p.get_height() > 0)
    # curious: position 1 S-A 4; 2: S-B 3, S-C 1; 3: S-C 2, S-B 1, none 1
    assert heights == [1, 1, 1, 2, 3, 4]
    assert "n=4" in fig.axes[0].get_title()


def test_neuromodulators(tables):
    episodes, _ = tables
    fig = fig_neuromodulators(episodes, run=2)
    assert len(fig.axes) == 4
    for ax in fig.axes:
        assert len(_data_lines(ax)) == 1
        assert len([line for line in ax.lines if line.get_gid() == EVENT_GID]) == 4  # 4 modules stored
    assert fig.axes[0].get_yscale() == "symlog"


def test_unknown_condition_or_run(tables):
    episodes, _ = tables
    with pytest.raises(ValueError, match="not in the results"):
        fig_cumulative_error(episodes, "lesion")
    with pytest.raises(ValueError, match="run 9 not in"):
        fig_neuromodulators(episodes, run=9)


def test_write_all(results_dir, tmp_path):
    paths = write_all(results_dir, tmp_path / "figs")
    names = sorted(p.name for p in paths)
    per_condition = ["cumulative_error", "intrinsic_reward", "neuromodulators", "reward_function"]
    expected = sorted(["order_counts.png", "learning_time.png"]
                      + [f"{k}_{c}.png" for k in per_condition for c in ("curious", "random_switching")])
    assert names == expected
    for path in paths:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert plt.get_fignums() == []  # no pyplot figure left open


@pytest.mark.parametrize(
    ("alpha", "expected"),
    [
        # eq 14 from R = 0: C1 0.5 after the reward 1, unchanged by NaN, 0.5*0.5 + 0.5*3 = 1.75
        (0.5, [[0.5, 0.0], [0.5, 1.0], [0.5, 1.0], [1.75, 1.0]]),
        (None, [[1.0, 0.0], [1.0, 2.0], [1.0, 2.0], [2.0, 2.0]]),  # sample average
    ],
)
def test_reward_estimates_by_hand(alpha, expected):
    run = pd.DataFrame({"context": [0, 1, 0, 0], "da": [1.0, 2.0, np.nan, 3.0]})
    np.testing.assert_allclose(_reward_estimates(run, 2, alpha), expected)
