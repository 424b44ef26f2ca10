"""The reachability study's statistics and rule (benchmarks/reach_study.py; docs/reproduction.md 2.11),
on the hand-made results folder (tests/analysis/fake_runs.py) and on hand-made per-draw rows."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "reach_study.py"
_spec = importlib.util.spec_from_file_location("reach_study", SCRIPT)
reach = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reach)


def test_draw_statistics_of_the_hand_made_runs(results):
    stats = reach.draw_statistics(results).set_index("condition")
    curious = stats.loc["curious"]
    # CURIOUS of fake_runs.py: 4 runs, S-A first in all, exact in runs 0 and 2, S-D in run 2, three learned in 0-2
    assert [curious[k] for k in ("runs", "S-A first", "exact order", "S-D stored", "all three learned")] \
        == [4, 4, 2, 1, 3]
    # contexts in blocks of 3 episodes of 100 frames (CYCLE): S-A at episode 10 has seen 6 episodes of C1/C2;
    # S-B 0.3 / 0.3 / 0.3 / 0.6 epochs and S-C 0.4 / 0.3 / 0.3 since the previous storage, by hand
    assert curious["S-A time"] == pytest.approx(0.6)
    assert curious["S-B time"] == pytest.approx(0.3) and curious["S-B learned"] == 4
    assert curious["S-C time"] == pytest.approx(0.3) and curious["S-C learned"] == 3


def _row(**values):
    row = {"runs": 16, "S-A first": 16, "exact order": 16, "S-D stored": 0, "all three learned": 16,
           "S-A time": 2.5, "S-B time": 15.0, "S-C time": 40.0}
    return {**row, **values}


def test_the_rule_at_its_boundaries():
    cases = [_row(), _row(**{"S-A first": 14}), _row(**{"S-A first": 13}), _row(**{"exact order": 9}),
             _row(**{"exact order": 8}), _row(**{"S-D stored": 2}), _row(**{"S-D stored": 3}),
             _row(**{"S-A time": 6.0}), _row(**{"S-A time": 6.2}), _row(**{"S-A time": 0.9}),
             _row(**{"S-B time": 7.5}), _row(**{"S-B time": 7.4}), _row(**{"S-C time": 80.0}),
             _row(**{"S-C time": np.nan})]
    met = reach.criteria(pd.DataFrame(cases))
    assert met["reached"].tolist() == [True, True, False, True, False, True, False, True, False, False, True, False,
                                       True, False]
    assert met["met"].tolist() == [6, 6, 5, 6, 5, 6, 5, 6, 5, 5, 6, 5, 6, 5]
    # the Clopper-Pearson ends of 25/25, 18/25, 0/25 at 95 %
    box = reach.bounds()
    assert box["S-A first"][0] == pytest.approx(0.025 ** (1 / 25))
    assert box["exact order"][0] == pytest.approx(0.5061, abs=1e-4)
    assert box["S-D stored"][1] == pytest.approx(1 - 0.025 ** (1 / 25))


def test_pairs_count_the_draws_meeting_both():
    met = reach.criteria(pd.DataFrame([_row(**{"S-A first": 10}), _row(**{"exact order": 2, "S-C time": 12.0}),
                                       _row()]))
    table = reach.pairs(met)
    assert table.loc["S-A first", "S-A first"] == 2 and table.loc["exact order", "S-C time"] == 2
    assert table.loc["S-A first", "exact order"] == 1 and table.loc["S-D stored", "S-D stored"] == 3
