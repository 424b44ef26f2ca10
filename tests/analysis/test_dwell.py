"""Visits, dwell, occupancy and the share of frames after an event, on hand-made runs with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from neuro_tables import episodes_of, results_of

from neurocur.analysis import (
    engagement,
    engagement_summary,
    occupancy,
    share_after,
    signal_over_time,
    summary,
    visits,
)
from neurocur.contexts.base import SourceSpec

SPEC = SourceSpec(("C1", "C2", "C3", "C4"), ("S-A", "S-B", "S-C", "S-D"), ("S-A", "S-B", "S-C"))


# contexts 0,0,1,1,1,0,2 with 100,100,100,200,100,100,50 frames: episodes start at
# 0, 100, 200, 300, 500, 600, 700 and the run ends at 750
RUN = episodes_of([0, 0, 1, 1, 1, 0, 2], [100, 100, 100, 200, 100, 100, 50])


def test_visits_are_maximal_runs_of_one_context():
    table = visits(RUN, SPEC)
    assert table["context"].tolist() == [0, 1, 0, 2]
    assert table["context_name"].tolist() == ["C1", "C2", "C1", "C3"]
    assert table["n_episodes"].tolist() == [2, 3, 1, 1]
    assert table["frames"].tolist() == [200, 400, 100, 50]
    assert table["step"].tolist() == [0, 200, 600, 700]
    assert table["first_episode"].tolist() == [0, 2, 5, 6]
    assert table["censored"].tolist() == [False, False, False, True]


def test_visits_never_span_two_runs():
    two = pd.concat([RUN, RUN.assign(run=1), RUN.assign(condition="random")], ignore_index=True)
    table = visits(two.sample(frac=1.0, random_state=0))       # row order does not matter
    assert len(table) == 12
    assert table.groupby(["condition", "run"])["visit"].max().tolist() == [3, 3, 3]


def test_engagement_per_context():
    table = engagement(RUN, SPEC).set_index("context")
    assert table.loc[0, "n_visits"] == 2
    assert table.loc[0, "mean_dwell_frames"] == 150.0 and table.loc[0, "mean_dwell_episodes"] == 1.5
    assert table.loc[1, "mean_dwell_frames"] == 400.0 and table.loc[1, "mean_dwell_episodes"] == 3.0
    assert table["share"].tolist()[:3] == pytest.approx([300 / 750, 400 / 750, 50 / 750])
    # a context of the world that was never visited
    assert table.loc[3, "n_visits"] == 0 and table.loc[3, "share"] == 0.0
    assert np.isnan(table.loc[3, "mean_dwell_frames"])
    assert table.loc[3, "context_name"] == "C4" and table.loc[3, "source"] == "S-D"
    assert len(engagement(RUN)) == 3                                  # without a spec: the contexts seen


def test_occupancy_in_bins_aligned_with_the_episodes():
    table = occupancy(RUN, bin_frames=300)
    share = table.pivot(index="bin", columns="context", values="share")
    assert share.loc[0].tolist() == pytest.approx([2 / 3, 1 / 3, 0.0])
    assert share.loc[1].tolist() == pytest.approx([0.0, 1.0, 0.0])
    assert share.loc[2].tolist() == pytest.approx([2 / 3, 0.0, 1 / 3])       # the partial last bin
    assert table.groupby("bin")["frames"].sum().tolist() == [300, 300, 150]
    assert table.groupby("bin")["step"].first().tolist() == [0, 300, 600]


def test_occupancy_splits_an_episode_at_a_bin_boundary():
    frames = occupancy(RUN, bin_frames=250).pivot(index="bin", columns="context", values="frames")
    assert frames.loc[0].tolist() == [200, 50, 0]          # episode 2 (context 1, 200-300) is split at 250
    assert frames.loc[1].tolist() == [0, 250, 0]
    assert frames.loc[2].tolist() == [100, 100, 50]
    assert frames.to_numpy().sum() == 750


def test_share_after_an_event():
    events = pd.DataFrame({"condition": ["curious"], "run": [0], "episode": [4]})
    table = share_after(RUN, "C3", events, SPEC)
    # after episode 4: episodes 5 (context 0, 100 frames) and 6 (context 2, 50 frames)
    assert table.loc[0, "frames_after"] == 150 and table.loc[0, "frames_in"] == 50
    assert table.loc[0, "share"] == pytest.approx(1 / 3)
    assert share_after(RUN, [0, 2], events).loc[0, "share"] == pytest.approx(1.0)
    whole = share_after(RUN, [1])
    assert whole.loc[0, "event_episode"] == -1 and whole.loc[0, "share"] == pytest.approx(400 / 750)


def test_share_after_an_event_that_never_happened_is_nan():
    two = pd.concat([RUN, RUN.assign(run=1)], ignore_index=True)
    events = pd.DataFrame({"condition": ["curious", "curious"], "run": [0, 1], "episode": [4, np.nan]})
    table = share_after(two, 2, events).set_index("run")
    assert table.loc[0, "share"] == pytest.approx(1 / 3)
    assert np.isnan(table.loc[1, "share"]) and np.isnan(table.loc[1, "frames_after"])
    assert np.isnan(share_after(two, 2, events.iloc[:1]).set_index("run").loc[1, "share"])   # no row: no event


def test_engagement_summary_over_runs():
    other = episodes_of([0, 1, 1, 1, 1, 1, 1], [100] * 7, run=1)       # 100 of 700 frames in context 0
    table = engagement_summary(pd.concat([RUN, other], ignore_index=True), SPEC).set_index("context")
    assert table.loc[0, "share"] == pytest.approx((300 / 750 + 100 / 700) / 2)
    assert table.loc[0, "dwell_frames"] == pytest.approx((150 + 100) / 2) and table.loc[0, "n_runs_visited"] == 2
    assert table.loc[0, "share_ci_low"] == pytest.approx(100 / 700) and table.loc[0, "share_ci_high"] == pytest.approx(0.4)
    assert table.loc[2, "n_runs_visited"] == 1 and table.loc[2, "dwell_frames"] == 50        # run 1 never visits C3
    assert table.loc[3, "n_runs_visited"] == 0 and np.isnan(table.loc[3, "dwell_frames"])


def test_summary_json_has_the_engagement(tables):
    rows = summary(results_of(*tables))["engagement"]
    c5 = next(r for r in rows if r["condition"] == "curious" and r["context_name"] == "C5")
    assert c5["share"] == pytest.approx(0.2) and c5["dwell_frames"] == pytest.approx(300.0)   # 3 episodes a visit


def test_a_signal_over_time_in_chosen_contexts():
    run = RUN.assign(da=np.arange(7.0))
    table = signal_over_time(run, "da", 300, contexts=["C2"], spec=SPEC)
    # context 1 (C2): episodes 2 (step 200), 3 (300) and 4 (500)
    assert table["bin"].tolist() == [0, 1] and table["step"].tolist() == [0, 300]
    assert table["da"].tolist() == [2.0, 3.5] and table["n_episodes"].tolist() == [1, 2]
    assert signal_over_time(run, "da", 300)["da"].tolist() == [1.0, 3.5, 5.5]
    with pytest.raises(ValueError, match="'ne_gain'"):
        signal_over_time(run, "ne_gain")


def test_the_swept_keys_are_carried():
    swept = RUN.assign(**{"LC.gain": 2.0})
    for table in (visits(swept), engagement(swept), occupancy(swept, 300), share_after(swept, 0),
                  signal_over_time(swept.assign(da=1.0), "da")):
        assert (table["LC.gain"] == 2.0).all()


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="unknown context 'TV'"):
        share_after(RUN, "TV", spec=SPEC)
    with pytest.raises(ValueError, match="no spec to name contexts"):
        share_after(RUN, "C1")
    with pytest.raises(ValueError, match="bin_frames"):
        occupancy(RUN, bin_frames=0)
    with pytest.raises(ValueError, match="'n_frames'"):
        visits(RUN.drop(columns="n_frames"))
    with pytest.raises(ValueError, match="no source spec for condition 'curious'"):
        engagement(RUN, {"random": SPEC})


def test_a_visit_ends_with_its_run():
    """Two runs, the first ending in the context the second starts in: two visits, one in each run."""
    one = episodes_of([0, 0, 1, 1, 0])
    table = visits(pd.concat([one, one.assign(run=1)], ignore_index=True))
    assert table.groupby("run").size().tolist() == [3, 3]
    assert table.groupby("run")["n_episodes"].apply(list).tolist() == [[2, 2, 1], [2, 2, 1]]
    assert table.groupby("run")["censored"].apply(list).tolist() == [[False, False, True]] * 2
