"""The worlds of the canonical tasks (docs/validation.md): vigilance trials, conditioning trials and
rewards that change by blocks of visits; their frames, their draws and their one-line errors."""

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from neurocur.config import ConfigError
from neurocur.contexts import build_world
from neurocur.contexts.conditioning import CUE, DELIVERED, DUE, ConditioningWorld
from neurocur.contexts.reward_blocks import RewardBlocksWorld
from neurocur.contexts.vigilance import VigilanceWorld


def test_vigilance_trials_show_a_target_or_a_distractor_at_the_onset():
    world = VigilanceWorld(trial_length=50, onset=10, duration=5, target_probability=0.3, crosstalk=0.4)
    first, _ = world.reset(seed=1)
    episodes = [first] + [world.step(0)[0] for _ in range(2999)]
    targets = np.array([e.frames[10, 0] == 1.0 for e in episodes])
    assert abs(targets.mean() - 0.3) < 4 * np.sqrt(0.3 * 0.7 / 3000)
    for e, t in zip(episodes[:50], targets):
        np.testing.assert_array_equal(e.frames[10:15], np.tile((1.0, 0.4) if t else (0.4, 1.0), (5, 1)))
        assert not e.frames[:10].any() and not e.frames[15:].any()
        np.testing.assert_array_equal(e.states, np.arange(50))
    again = VigilanceWorld(trial_length=50, onset=10, duration=5, target_probability=0.3, crosstalk=0.4)
    np.testing.assert_array_equal(again.reset(seed=1)[0].frames, first.frames)


def test_conditioning_trials_omit_rewards_only_after_training():
    world = ConditioningWorld(trial_length=20, cue=3, cue_duration=2, delay=8, reward=1.5, omit_after=100,
                              omission_probability=0.5)
    first, _ = world.reset(seed=2)
    episodes = [first] + [world.step(0)[0] for _ in range(399)]
    omitted = np.array([e.frames[11, DELIVERED] == 0.0 for e in episodes])
    assert not omitted[:100].any() and 0.4 < omitted[100:].mean() < 0.6
    for e, o in zip(episodes, omitted):
        assert e.reward == (0.0 if o else 1.5)
        np.testing.assert_array_equal(np.flatnonzero(e.frames[:, CUE]), [3, 4])
        np.testing.assert_array_equal(np.flatnonzero(e.frames[:, DUE]), [11])


def test_reward_blocks_pay_by_visits_over_every_context():
    world = build_world(
        {"type": "reward_blocks", "contexts": ["S-A", "S-B"], "visit_length": 5, "frame_shape": [3, 3],
         "blocks": [[1.0, 0.2], [0.0, 0.5]], "block_visits": 3})
    assert isinstance(world, RewardBlocksWorld)
    first, _ = world.reset(seed=0, context=0)
    rewards = [first.reward] + [world.step(c)[0].reward for c in (1, 0, 0, 1, 0, 1)]
    assert rewards == [1.0, 0.2, 1.0, 0.0, 0.5, 0.0, 0.5]  # the last block goes on
    world.reset(seed=0, context=1)  # the first visit is the block's first
    assert world.visits(1, 4).reward == pytest.approx(0.2 * 2 + 0.5 * 2)  # four visits that span two blocks


def test_reward_blocks_default_to_one_block_paying_one_per_context():
    """Without ``blocks`` every visit of every context pays 1.0 (one block), whatever the contexts."""
    for table in ({"type": "reward_blocks"}, {"type": "reward_blocks", "contexts": ["S-A", "S-B", "S-C"]}):
        world = build_world({**table, "visit_length": 5, "frame_shape": [3, 3], "block_visits": 2})
        n = world.n_contexts
        assert world.params.blocks == ((1.0,) * n,)
        first, _ = world.reset(seed=0, context=0)
        assert [first.reward] + [world.step(c % n)[0].reward for c in range(7)] == [1.0] * 8
    env = gymnasium.make("neurocur/RewardBlocks-v0")  # every parameter its default: the paper's five contexts
    assert env.unwrapped.world.params.blocks == ((1.0,) * 5,)
    _, info = env.reset(seed=1)
    assert env.step(3)[1] == 1.0
    world = RewardBlocksWorld(("S-A", "S-B"), visit_length=5, frame_shape=(3, 3))  # keywords, as SyntheticWorld's
    assert world.params.blocks == ((1.0, 1.0),) and world.params.block_visits == 500
    first, _ = world.reset(seed=0, context=1)
    assert (first.reward, world.step(0)[0].reward) == (1.0, 1.0)


@pytest.mark.parametrize("table, match", [
    ({"type": "vigilance", "onset": 180, "duration": 40}, r"key 'world.duration': expected at most "
                                                          r"trial_length - onset = 20, got 40"),
    ({"type": "conditioning", "cue": 5, "delay": 20}, r"key 'world.delay': expected less than "
                                                      r"trial_length - cue = 20, got 20"),
    ({"type": "reward_blocks", "contexts": ["S-A", "S-B"], "blocks": [[1.0]]},
     r"key 'world.blocks\[0\]': expected 2 rewards \(one per context\), got \[1.0\]"),
    ({"type": "reward_blocks", "contexts": ["S-A"], "rewards": [1.0]}, r"key 'world.rewards': expected no rewards table"),
])
def test_bad_world_tables_name_the_key(table, match):
    with pytest.raises(ConfigError, match=match):
        build_world(table)


@pytest.mark.parametrize("table", [{"type": "vigilance"}, {"type": "conditioning"},
                                   {"type": "reward_blocks", "contexts": ["S-A", "S-B"], "visit_length": 5,
                                    "frame_shape": [3, 3], "blocks": [[1.0, 0.0]]}])
def test_task_worlds_are_gymnasium_environments(table):
    check_env(build_world(table).as_env(), skip_render_check=True)
