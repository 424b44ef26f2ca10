"""Event-locked DA/NE averages and tonic against phasic NE, on hand-made runs with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from neuro_tables import episodes_of
from scipy import stats as sps

from neurocur.analysis import event_locked_average, events, tonic_phasic, tonic_phasic_correlation

# episodes 0..7: modules stored at 3 and 7, contexts switch at 2, 5 and 6, familiarity starts at 1 and 4
RUN = episodes_of([0, 0, 1, 1, 1, 2, 0, 0], module_learned=[0, 0, 0, 1, 0, 0, 0, 1],
                  familiar=[0, 1, 1, 0, 1, 1, 0, 0], da=np.arange(8.0),
                  ne_tonic=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8], ne_phasic=[0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1],
                  ne_gain=1.0)


def test_events_of_each_kind():
    table = events(RUN)
    by_kind = table.groupby("event")["episode"].apply(list).to_dict()
    assert by_kind == {"module_stored": [3, 7], "context_switch": [2, 5, 6], "familiarity_onset": [1, 4]}
    assert table.loc[table["event"] == "context_switch", "context"].tolist() == [1, 2, 0]
    two = pd.concat([RUN, RUN.assign(run=1)], ignore_index=True)
    assert (events(two, "context_switch").groupby("run").size() == 3).all()      # none across runs
    assert list(events(RUN.drop(columns="familiar"))["event"].unique()) == ["module_stored", "context_switch"]


def test_the_event_locked_average_of_a_ramp():
    table = event_locked_average(RUN, "da", "module_stored", window=2)
    # da = episode index; events at 3 and 7 of episodes 0..7: lag 1 and 2 exist only for the first
    assert table["lag"].tolist() == [-2, -1, 0, 1, 2]
    assert table["mean"].tolist() == [3.0, 4.0, 5.0, 4.0, 5.0]
    assert table["n_events"].tolist() == [2] * 5 and table["n_runs"].tolist() == [1] * 5
    assert table["ci_low"].tolist() == table["mean"].tolist()       # one run: the bootstrap has one value
    assert event_locked_average(RUN, "da", "module_stored", window=0, interval="t")["ci_low"].isna().all()


def test_runs_weigh_equally_and_the_interval_is_students_t():
    one = RUN.assign(da=1.0)                                         # 2 module events
    other = episodes_of([0] * 8, run=1, module_learned=[1, 0, 1, 0, 1, 0, 0, 0], familiar=False, da=3.0)
    table = event_locked_average(pd.concat([one, other], ignore_index=True), "da", "module_stored", window=0,
                                 interval="t")
    row = table.iloc[0]
    assert row["mean"] == 2.0 and row["n_runs"] == 2 and row["n_events"] == 5    # not (2·1 + 3·3)/5
    half = sps.t.ppf(0.975, 1) * np.sqrt(2) / np.sqrt(2)
    assert (row["ci_low"], row["ci_high"]) == pytest.approx((2.0 - half, 2.0 + half))
    boot = event_locked_average(pd.concat([one, other], ignore_index=True), "da", "module_stored",
                                window=0).iloc[0]
    assert boot["ci_low"] == 1.0 and boot["ci_high"] == 3.0


def test_per_context_and_default_signals():
    table = event_locked_average(RUN, kinds="context_switch", window=0, by_context=True)
    assert set(table["signal"]) == {"da", "ne_tonic", "ne_phasic", "ne_gain"}
    da = table[table["signal"] == "da"].set_index("context")["mean"]
    assert da.to_dict() == {0: 6.0, 1: 2.0, 2: 5.0}


def test_missing_values_are_left_out():
    table = event_locked_average(RUN.assign(da=[0, 1, 2, np.nan, 4, 5, 6, 7.0]), "da", "module_stored", window=0)
    assert table["mean"].tolist() == [7.0]


def test_tonic_against_phasic():
    two = pd.concat([RUN, RUN.assign(run=1, ne_phasic=RUN["ne_tonic"])], ignore_index=True)
    scatter = tonic_phasic(two).set_index(["run", "context"])
    assert scatter.loc[(0, 1), "n_episodes"] == 3
    assert scatter.loc[(0, 1), "ne_tonic"] == pytest.approx(0.4) and scatter.loc[(0, 1), "ne_phasic"] == pytest.approx(0.5)
    rho = tonic_phasic_correlation(two).iloc[0]
    assert rho["rhos"] == pytest.approx([-1.0, 1.0]) and rho["mean_rho"] == pytest.approx(0.0)
    assert tonic_phasic_correlation(RUN.assign(ne_tonic=0.5)).iloc[0]["n_runs"] == 0      # constant: no ρ


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="unknown event kind"):
        event_locked_average(RUN, kinds="reward")
    with pytest.raises(ValueError, match="window"):
        event_locked_average(RUN, window=-1)
    with pytest.raises(ValueError, match="'familiar'"):
        events(RUN.drop(columns="familiar"), "familiarity_onset")
    with pytest.raises(ValueError, match="'ne_tonic'"):
        tonic_phasic(RUN.drop(columns="ne_tonic"))


def test_an_event_window_stops_at_its_runs_end():
    """Run 0's module stored at its last episode: the lags after it are past the run's end, not run 1's
    first episodes. Lag 1 is then run 0's other event alone (da 4) beside run 1's (da 104)."""
    two = pd.concat([RUN, RUN.assign(run=1, da=RUN["da"] + 100.0)], ignore_index=True)
    table = event_locked_average(two, "da", "module_stored", window=2).set_index("lag")
    assert table.loc[1, "mean"] == (4.0 + 104.0) / 2 and table.loc[2, "mean"] == (5.0 + 105.0) / 2
