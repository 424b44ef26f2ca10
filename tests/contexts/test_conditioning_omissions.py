"""The conditioning world's omission schedule, pinned against the documented rule drawn independently.

The rule (:mod:`neurocur.contexts.conditioning`): trials are counted from 0 in each run; from trial
``omit_after`` on, each trial's reward is omitted with probability ``omission_probability``, one
``random()`` draw of the world's generator per such trial (omitted when the draw is below the
probability), none before. ``reset(seed=s)`` seeds the generator with ``numpy.random.default_rng(s)``.
A schedule that starts one trial late spares trial ``omit_after`` and shifts every later draw by one trial.
"""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.contexts.conditioning import DELIVERED, ConditioningWorld

KW = dict(trial_length=20, cue=3, cue_duration=2, delay=8, reward=1.5)
DUE_STEP = 3 + 8


def run(world, n, seed=None):
    """The first ``n`` trials of a new run (seeded when ``seed`` is given): whether each one's reward was omitted."""
    first, _ = world.reset(seed=seed)
    episodes = [first] + [world.step(0)[0] for _ in range(n - 1)]
    omitted = np.array([e.frames[DUE_STEP, DELIVERED] == 0.0 for e in episodes])
    np.testing.assert_array_equal([e.reward for e in episodes], np.where(omitted, 0.0, 1.5))
    return omitted


def documented(rng, n, omit_after, p):
    """The documented rule, drawn from ``rng``: one draw per trial from trial ``omit_after`` on."""
    return np.array([t >= omit_after and rng.random() < p for t in range(n)])


@pytest.mark.parametrize("omit_after", [0, 1, 7])
def test_the_omission_schedule_of_a_seed_is_the_documented_rule(omit_after):
    world = ConditioningWorld(**KW, omit_after=omit_after, omission_probability=0.5)
    rng = np.random.default_rng(4)
    expected = documented(rng, 40, omit_after, 0.5)
    np.testing.assert_array_equal(run(world, 40, seed=4), expected)
    # a new run counts its trials from 0 again and goes on drawing from the same generator
    np.testing.assert_array_equal(run(world, 40), documented(rng, 40, omit_after, 0.5))
    # pinned by hand too: the first omitted trials of seed 4 are those whose draw is below 0.5
    draws = np.random.default_rng(4).random(40 - omit_after)
    first = omit_after + np.flatnonzero(draws < 0.5)[:5]
    np.testing.assert_array_equal(np.flatnonzero(expected)[:5], first)


@pytest.mark.parametrize("omit_after", [0, 1, 7])
def test_omissions_start_at_trial_omit_after_exactly(omit_after):
    """At probability 1 every trial from ``omit_after`` on is a probe and none before: the first omitted
    trial is ``omit_after`` itself, in every run."""
    world = ConditioningWorld(**KW, omit_after=omit_after, omission_probability=1.0)
    for seed in (0, None):
        omitted = run(world, omit_after + 5, seed=seed)
        assert np.flatnonzero(omitted)[0] == omit_after
        assert not omitted[:omit_after].any() and omitted[omit_after:].all()
