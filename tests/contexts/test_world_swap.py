"""The synthetic world's swap (a world event): from ``swap_at`` frames on, each context shows its
``swap`` source, its clock going on; stored modules are credited to the source shown when stored."""

import numpy as np
import pandas as pd
import pytest

from neurocur.config import ConfigError
from neurocur.contexts import build_world

TABLE = {"contexts": ["S-A", "S-B"], "swap": ["S-A", "S-E"], "swap_at": 60, "visit_length": 20,
         "frame_shape": [4, 4], "sources": {"S-E": {"sinusoid": 36}}, "clock_offsets": "zero"}


def test_the_swap_takes_effect_at_the_first_visit_after_swap_at():
    world = build_world(TABLE)
    first, _ = world.reset(seed=0, context=1)
    visits = [first] + [world.step(1)[0] for _ in range(4)]  # frames 0-99; visits start at 0, 20, 40, 60, 80
    assert world.source_names == ("S-A", "S-E")
    plain = build_world({k: v for k, v in TABLE.items() if k not in ("swap", "swap_at")} | {"contexts": ["S-A", "S-B"]})
    plain.reset(seed=0, context=1)
    for v in visits[:3]:  # before the swap: S-B's frames
        np.testing.assert_array_equal(v.frames, plain.context_frames(1)[v.states])
    rendered = world.context_frames(1)  # S-E's frames, under this run's mixing
    for v in visits[3:]:
        np.testing.assert_array_equal(v.frames, rendered[v.states])
        assert not np.allclose(v.frames, plain.context_frames(1)[v.states])
    np.testing.assert_array_equal(visits[3].states, np.arange(60, 80))  # the clock goes on
    world.reset(seed=0)
    assert world.source_names == ("S-A", "S-B")  # a new run starts before the swap


def test_modules_are_credited_to_the_source_shown_when_stored():
    world = build_world(TABLE)
    world.reset(seed=0)
    assert [world.source_at(1, s) for s in (0, 59, 60, 1000)] == ["S-B", "S-B", "S-E", "S-E"]
    assert world.source_at(0, 100) == "S-A"


def test_a_swap_of_the_wrong_length_names_the_key():
    with pytest.raises(ConfigError, match=r"key 'world.swap': expected 2 source names \(one per context\)"):
        build_world(TABLE | {"swap": ["S-A"]})
    with pytest.raises(ConfigError, match=r"key 'world.contexts': expected source names among"):
        build_world(TABLE | {"swap": ["S-A", "S-Z"]})


def test_relearning_statistics_read_the_credited_sources():
    from neurocur.analysis.stats.validation import relearning_per_run, relearning_test

    episodes = pd.DataFrame({"condition": ["a"] * 2 + ["b"] * 2, "run": [0, 1, 0, 1], "step": [900, 900, 900, 900],
                             "n_frames": [100] * 4})
    modules = pd.DataFrame({"condition": ["a", "a", "b"], "run": [0, 1, 0], "source": ["S-E", "S-E", "S-B"],
                            "step": [300, 50, 400]})
    runs = relearning_per_run(episodes, modules, 100, "S-E")
    assert runs["relearned"].tolist() == [True, False, False, False]  # run 1's S-E module predates the swap
    assert runs["frames_to_relearn"].tolist() == [200, 900, 900, 900]
    test = relearning_test(runs, "a", "b")
    assert (test["relearned_a"], test["relearned_b"], test["mean_frames_a"]) == (1, 0, 550.0)
