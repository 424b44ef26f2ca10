"""The canonical tasks' figures draw each condition on its own (neurocur.analysis.figures.validation)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.figures.validation import fig_conditioning


def conditioning_table(condition: str, cue: float, runs: int = 2, trials: int = 30) -> pd.DataFrame:
    """Trials of a conditioning world whose DA at the cue is ``cue`` + the run, the reward's 1 - the trial/100."""
    rows = [{"condition": condition, "run": r, "episode": k, "omitted": k == trials - 1, "da_cue": cue + r,
             "da_reward": 1.0 - k / 100, "da_baseline": 0.0} for r in range(runs) for k in range(trials)]
    return pd.DataFrame(rows)


def test_each_condition_has_its_own_row_of_panels():
    episodes = pd.concat([conditioning_table("td", 0.5), conditioning_table("lesioned", 3.0)], ignore_index=True)
    fig = fig_conditioning(episodes)
    axes = np.array(fig.axes).reshape(2, 2)
    for row, (condition, cue) in enumerate((("td", 1.0), ("lesioned", 3.5))):  # the mean over runs 0 and 1
        cue_line, reward_line = axes[row, 0].lines[:2]
        assert axes[row, 0].get_title().startswith(f"{condition}: ")
        np.testing.assert_allclose(cue_line.get_ydata(), cue)
        np.testing.assert_allclose(reward_line.get_ydata(), 1.0 - np.arange(29) / 100)
        early_cue = axes[row, 1].patches[0].get_height()
        assert early_cue == pytest.approx(cue)


def test_one_condition_keeps_the_plain_titles():
    fig = fig_conditioning(conditioning_table("td", 0.5))
    assert len(fig.axes) == 2 and fig.axes[0].get_title() == "DA moves from the reward to the cue"
    np.testing.assert_allclose(fig.axes[0].lines[0].get_ydata(), 1.0)
