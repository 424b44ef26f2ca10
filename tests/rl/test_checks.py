"""neurocur.rl checks what it is given: defaults that fit the observation's size for every shipped
VTA model; and two statistics against closed forms on hand-made environments: the pass reward
summed over the block and the vector wrapper's decay per step."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.regions import REGIONS
from neurocur.rl import IntrinsicReward, IntrinsicRewardVector

pytestmark = [pytest.mark.filterwarnings("ignore::UserWarning"), pytest.mark.filterwarnings("error::RuntimeWarning")]

VTA_MODELS = [name for name in REGIONS.names() if name.startswith("vta.")]


class Scripted(gym.Env):
    """A never-ending environment on ``space``: the observation of step t (0: the reset's) is
    ``observe(t, rng)``, its reward ``reward(t)``; ``rng`` is the environment's seeded generator."""

    action_space = gym.spaces.Discrete(2)

    def __init__(self, space, observe, reward=lambda t: 0.0):
        self.observation_space, self.observe, self.reward = space, observe, reward

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return self.observe(0, self.np_random), {}

    def step(self, action):
        self.t += 1
        return self.observe(self.t, self.np_random), self.reward(self.t), False, False, {}


def uniform(space):
    return lambda t, rng: rng.uniform(space.low, space.high).astype(space.dtype)


def run(env, steps, seed=0):
    env.reset(seed=seed)
    return [env.step(env.action_space.sample())[4] for _ in range(steps)]


@pytest.mark.parametrize("env_id", ["MountainCar-v0", "CartPole-v1", "Pendulum-v1"])
@pytest.mark.parametrize("model", VTA_MODELS)
def test_every_shipped_vta_model_wraps_the_classic_controls_with_its_defaults(model, env_id):
    """Each ``vta.*`` model with the wrapper's defaults: EC's n_pca and n_components fit the
    observation's values (MountainCar has 2, as the learners' n_pca=None does), two passes run."""
    env = gym.make(env_id)
    wrapped = IntrinsicReward(env, model)
    wrapped.reset(seed=0)
    frames = wrapped.curiosity.frames
    bonus = [wrapped.step(wrapped.action_space.sample())[4]["intrinsic_reward"] for _ in range(2 * frames + 1)]
    assert np.all(np.isfinite(bonus))
    assert len(wrapped.sensory.simulator.episodes()) == (2 if frames > 1 else 3)
    ec = wrapped.sensory.circuit.specs.get("EC")
    if ec is not None:
        n = env.observation_space.shape[0]
        assert (ec.params.n_pca or min(3, n)) <= n and ec.params.n_components <= n


def test_a_single_value_observation_fits_one_slow_feature():
    space = gym.spaces.Box(0.0, 1.0, (1,), np.float64)
    env = IntrinsicReward(Scripted(space, uniform(space)), "vta.surprise", frames=4)
    bonus = [info["intrinsic_reward"] for info in run(env, 200)]
    ec = env.sensory.circuit.specs["EC"].params
    assert (ec.n_pca, ec.n_components) == (None, 1)
    assert len(env.sensory.simulator.episodes()) == 50 and np.count_nonzero(bonus) > 10


def test_explicit_sizes_above_the_observations_values_are_still_refused():
    with pytest.raises(ConfigError, match=r"^IntrinsicReward overrides: key 'EC.n_pca': expected at most the 2 values"):
        IntrinsicReward(gym.make("MountainCar-v0"), "vta.surprise", overrides={"EC.n_pca": 3})
    with pytest.raises(ConfigError, match=r"'EC.n_components': expected at most the 2 values.*got 3$"):
        IntrinsicReward(gym.make("MountainCar-v0"), "vta.surprise", overrides={"EC.n_components": 3, "EC.n_pca": None})


def test_the_pass_reward_is_the_blocks_summed_extrinsic_reward():
    """``vta.mixture`` with weight 1 releases the pass's reward as DA: the bonus of the step that
    closes a block of 4 is the sum of the block's 4 rewards (each step's reward differs), 0 elsewhere."""
    space = gym.spaces.Box(0.0, 1.0, (3,), np.float64)
    rewards = np.random.default_rng(8).normal(size=200)
    env = IntrinsicReward(Scripted(space, uniform(space), lambda t: float(rewards[t - 1])), "vta.mixture",
                          params={"weight": 1.0}, frames=4, scale=0.5)
    bonus = np.array([info["intrinsic_reward"] for info in run(env, 120)])
    expected = np.zeros(120)
    expected[3::4] = 0.5 * rewards[:120].reshape(30, 4).sum(axis=1)
    np.testing.assert_allclose(bonus, expected, rtol=1e-12, atol=1e-15)
    assert len(env.sensory.simulator.episodes()) == 30


def test_the_vector_wrapper_decays_the_bonus_once_per_step():
    """3 sub-environments, count novelty: the bonus of sub-environment i at vector step t is
    ``scale * decay**t / sqrt(N)``, N the visits of its grid cell counted by hand in index order."""
    space = gym.spaces.Box(0.0, 1.0, (2,), np.float64)
    envs = gym.vector.SyncVectorEnv([lambda: Scripted(space, uniform(space))] * 3)
    wrapped = IntrinsicRewardVector(envs, "vta.novelty", scale=2.0, decay=0.9)
    wrapped.reset(seed=4)
    counts: dict[int, int] = {}
    for t in range(40):
        obs, _, _, _, info = wrapped.step(np.zeros(3, dtype=int))
        for i in range(3):
            cell = np.minimum((obs[i] * 8).astype(int), 7)
            key = int(cell[0] + 8 * cell[1])
            counts[key] = counts.get(key, 0) + 1
            assert info["intrinsic_reward"][i] == pytest.approx(2.0 * 0.9**t / np.sqrt(counts[key]), rel=1e-12)
    assert max(counts.values()) > 1
