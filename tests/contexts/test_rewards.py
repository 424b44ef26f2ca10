"""Extrinsic reward per context: schedules reach Episode.reward in every world type; bad input."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.contexts import build_world
from neurocur.contexts.gym import GymWorld
from neurocur.contexts.icub import ICubParams, ICubWorld, cache_file
from neurocur.contexts.icub_data import FRAME_SHAPE, EpisodePool, _save
from neurocur.contexts.rewards import Rewards
from neurocur.contexts.synthetic import SyntheticWorld

REWARDS = [0, 0, 1.5, [1, 0, 0], -2]


def _visits(world, contexts, seed=0):
    """Rewards of a reset to ``contexts[0]`` and steps to the rest: (episode rewards, step rewards)."""
    first, _ = world.reset(seed=seed, context=contexts[0])
    paid, returned = [first.reward], [first.reward]
    for c in contexts[1:]:
        ep, reward, terminated, truncated, _ = world.step(c)
        assert not terminated and not truncated
        paid.append(ep.reward)
        returned.append(reward)
    return paid, returned


def _expected(rewards, contexts):
    """The schedule read by hand: visit k of context c pays schedule[k % len]."""
    counts, out = {}, []
    for c in contexts:
        entry = rewards[c]
        schedule = entry if isinstance(entry, list) else [entry]
        k = counts.get(c, 0)
        counts[c] = k + 1
        out.append(float(schedule[k % len(schedule)]))
    return out


def test_synthetic_rewards_follow_each_contexts_own_schedule():
    world = SyntheticWorld(rewards=REWARDS, frame_shape=(4, 4))
    contexts = [3, 2, 3, 0, 3, 3, 4, 3, 1, 3]
    paid, returned = _visits(world, contexts)
    # context 3 pays 1, 0, 0, 1, 0, 0 on its own visits, whatever is visited in between
    assert paid == returned == [1.0, 1.5, 0.0, 0.0, 0.0, 1.0, -2.0, 0.0, 0.0, 0.0]
    assert paid == _expected(REWARDS, contexts)
    # a new run restarts the counts
    assert _visits(world, contexts, seed=1)[0] == paid


def test_without_rewards_every_visit_pays_zero_and_the_random_stream_is_unchanged():
    plain, paying = SyntheticWorld(frame_shape=(4, 4)), SyntheticWorld(rewards=REWARDS, frame_shape=(4, 4))
    assert plain.rewards is None
    contexts = [4, 4, 3, 4, 0, 4] * 5
    assert _visits(plain, contexts)[0] == [0.0] * len(contexts)
    a, b = plain.reset(seed=3, context=4)[0], paying.reset(seed=3, context=4)[0]
    for c in contexts:  # S-D (context 4) is redrawn from the world's generator: rewards draw nothing
        np.testing.assert_array_equal(a.frames, b.frames)
        a, b = plain.step(c)[0], paying.step(c)[0]


def test_a_world_as_gymnasium_env_returns_the_reward():
    env = SyntheticWorld(rewards=REWARDS, frame_shape=(4, 4)).as_env()
    env.reset(seed=0, options={"context": 2})
    assert [env.step(3)[1] for _ in range(4)] == [1.0, 0.0, 0.0, 1.0]


def test_gym_world_rewards():
    world = GymWorld(["CartPole-v1", "Pendulum-v1"], visit_length=3, frame_shape=(4, 6), rewards=[[0, 2], 0.5])
    contexts = [0, 0, 1, 0, 1, 0]
    paid, returned = _visits(world, contexts)
    world.close()
    assert paid == returned == _expected([[0, 2], 0.5], contexts) == [0.0, 2.0, 0.5, 0.0, 0.5, 2.0]


@pytest.fixture
def icub_cache(tmp_path):
    """A cached iCub data set of 3 tiny made-up episodes per context (no simulation needed)."""
    rng = np.random.default_rng(0)
    n, length = 3, 5
    pools = {obj: EpisodePool(frames=rng.integers(0, 256, (n * length, *FRAME_SHAPE), dtype=np.uint8),
                              states=np.tile(np.arange(length), n).astype(np.int64),
                              positions=rng.random((n * length, 3)),
                              offsets=np.arange(0, n * length + 1, length, dtype=np.int64),
                              contact=np.full(n, 2, dtype=np.int64))
             for obj in ("topple", "roll")}
    _save(cache_file(ICubParams(n_episodes=n, dataset_seed=0, cache_dir=str(tmp_path))), pools)
    return tmp_path


def test_icub_world_rewards(icub_cache):
    world = ICubWorld(n_episodes=3, seed=0, cache_dir=icub_cache, rewards=[[1, 0], 3])
    contexts = [0, 1, 0, 0, 1, 0]
    paid, returned = _visits(world, contexts)
    assert paid == returned == [1.0, 3.0, 0.0, 1.0, 3.0, 0.0]


def test_rewards_from_a_world_table(icub_cache):
    world = build_world({"type": "icub", "n_episodes": 3, "cache_dir": str(icub_cache), "rewards": [0, [5, 6]]})
    assert _visits(world, [1, 1, 1])[0] == [5.0, 6.0, 5.0]
    world = build_world({"contexts": ["S-A", "S-D"], "frame_shape": [4, 4], "rewards": [[0.25], 1]})
    assert _visits(world, [0, 1, 0])[0] == [0.25, 1.0, 0.25]


def test_rewards_reset_and_count_per_context():
    rewards = Rewards([1.0, (2.0, 3.0)])
    assert [rewards.pay(1), rewards.pay(0), rewards.pay(1), rewards.pay(1)] == [2.0, 1.0, 3.0, 2.0]
    rewards.reset()
    assert rewards.pay(1) == 2.0
    assert Rewards.of(None) is None


@pytest.mark.parametrize("rewards, key, expected", [
    ([0, 1], "rewards", "a list of 5 entries (one per context: C1, C2, C3, C4, C5)"),
    ([0, 0, 0, 0, 0, 0], "rewards", "a list of 5 entries"),
    ([0, 0, [], 0, 0], "rewards[2]", "a number or a schedule (a non-empty list of numbers"),
    ([0, 0, [1, "x"], 0, 0], "rewards[2][1]", "a number"),
    ([0, 0, float("nan"), 0, 0], "rewards[2]", "a number"),
    ([0, True, 0, 0, 0], "rewards[1]", "a number"),
    ([], "rewards", "a list of at least 1 item"),
    (1.0, "rewards", "a list of at least 1 item"),
])
def test_bad_rewards_name_the_key_and_what_was_expected(rewards, key, expected):
    with pytest.raises(ConfigError, match=r"key '(.*)'") as info:
        SyntheticWorld(rewards=rewards)
    assert info.value.key == key and expected in info.value.expected


def test_bad_rewards_of_gym_and_icub_worlds_name_the_length():
    with pytest.raises(ConfigError, match=r"key 'rewards': expected a list of 2 entries \(one per context: "
                                          r"CartPole-v1, Pendulum-v1\)"):
        GymWorld(["CartPole-v1", "Pendulum-v1"], rewards=[1, 2, 3])
    with pytest.raises(ConfigError, match=r"key 'world.rewards': expected a list of 2 entries \(one per context: "
                                          r"topple, roll\).*got 1 entries"):
        build_world({"type": "icub", "rewards": [1]})


def test_an_experiment_file_with_a_reward_list_of_the_wrong_length(tmp_path):
    from neurocur.experiments import load_experiment

    path = tmp_path / "exp.toml"
    path.write_text('circuit = "cd_misfa"\nruns = 1\nsteps = 100\n[world]\nrewards = [0, 1]\n'
                    '[conditions.a]\n[conditions.b]\nworld = { rewards = [0, 0, [1, 0], 0, 0] }\n')
    with pytest.raises(ConfigError) as info:
        load_experiment(path)
    assert str(path) in str(info.value) and info.value.key == "world.rewards"
    assert "a list of 5 entries (one per context" in info.value.expected
    path.write_text('circuit = "cd_misfa"\nruns = 1\nsteps = 100\n[world]\nrewards = [0, 0, [1, 0], 0, 0]\n')
    cond = next(iter(load_experiment(path).conditions.values()))
    assert cond.world_params.rewards == (0.0, 0.0, (1.0, 0.0), 0.0, 0.0)
