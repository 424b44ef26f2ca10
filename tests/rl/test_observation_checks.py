"""neurocur.rl checks what it is given: observations against the observation space (shape, dtype,
finite values; out-of-bounds values clipped and counted), spaces whose bounds overflow the coder,
defaults that fit the observation's size for every shipped VTA model, and two statistics against
closed forms: the pass reward summed over the block and the vector wrapper's decay per step."""

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


BOX4 = gym.spaces.Box(-1.0, 1.0, (4,), np.float32)


def uniform(space):
    return lambda t, rng: rng.uniform(space.low, space.high).astype(space.dtype)


def spoiled(at, how, space=BOX4):
    """Uniform observations of ``space`` but at step ``at``, where ``how`` turns the observation into another."""
    draw = uniform(space)
    return lambda t, rng: how(draw(t, rng)) if t == at else draw(t, rng)


def with_value(index, value):
    def how(x):
        x = x.astype(np.float64)
        x[index] = value
        return x
    return how


def run(env, steps, seed=0):
    env.reset(seed=seed)
    return [env.step(env.action_space.sample())[4] for _ in range(steps)]


# the count path (a grid, SimHash) and the slow-feature path (a grid, SimHash)
PATHS = [("vta.novelty", {}), ("vta.novelty", {"contexts": "simhash"}),
         ("vta.learning_progress", {"frames": 4}), ("vta.surprise", {"frames": 4, "contexts": "simhash"})]


@pytest.mark.parametrize("model, options", PATHS)
@pytest.mark.parametrize("value, shown", [(np.nan, "nan"), (np.inf, "inf"), (-np.inf, "-inf")])
def test_a_non_finite_observation_is_one_line_naming_the_step_and_the_index(model, options, value, shown):
    env = IntrinsicReward(Scripted(BOX4, spoiled(7, with_value(2, value))), model, **options)
    with pytest.raises(ValueError, match=rf"^IntrinsicReward step 7: key 'observation\[2\]': expected a finite "
                                         rf"number \(observation space Box.*\), got {shown}$"):
        run(env, 20)


@pytest.mark.parametrize("model, options", PATHS)
def test_a_non_finite_reset_observation_is_refused_too(model, options):
    env = IntrinsicReward(Scripted(BOX4, spoiled(0, with_value(0, np.nan))), model, **options)
    with pytest.raises(ValueError, match=r"^IntrinsicReward reset: key 'observation\[0\]': expected a finite number"):
        env.reset(seed=0)


@pytest.mark.parametrize("model, options", PATHS)
@pytest.mark.parametrize("size", [3, 5])
def test_a_misshaped_observation_is_refused(model, options, size):
    env = IntrinsicReward(Scripted(BOX4, spoiled(5, lambda x: np.resize(x, size))), model, **options)
    with pytest.raises(ValueError, match=rf"^IntrinsicReward step 5: key 'observation': expected an array of shape "
                                         rf"\(4,\) \(observation space Box.*\), got an array of shape \({size},\)$"):
        run(env, 20)


@pytest.mark.parametrize("bad, shown", [(lambda x: x.astype(complex), "complex128"),
                                        (lambda x: x.astype(object), "object"),
                                        (lambda x: x.astype(str), "<U")])
def test_an_observation_that_is_not_real_numbers_is_refused(bad, shown):
    env = IntrinsicReward(Scripted(BOX4, spoiled(3, bad)), "vta.novelty")
    with pytest.raises(ValueError, match=rf"^IntrinsicReward step 3: key 'observation': expected real numbers "
                                         rf"\(bool, integer or float\) \(observation space Box.*\), got dtype {shown}"):
        run(env, 10)


@pytest.mark.parametrize("model, options", PATHS)
def test_a_reward_that_is_not_finite_is_refused(model, options):
    env = IntrinsicReward(Scripted(BOX4, uniform(BOX4), lambda t: np.nan if t == 6 else 1.0), model, **options)
    with pytest.raises(ValueError, match=r"^IntrinsicReward step 6: key 'reward': expected a finite number, got nan$"):
        run(env, 10)


def test_an_image_observation_is_checked_with_its_pixel_named():
    space = gym.spaces.Box(0, 255, (6, 5, 3), np.uint8)
    image = uniform(space)
    env = IntrinsicReward(Scripted(space, spoiled(4, with_value((2, 1, 0), np.nan), space)), "vta.surprise",
                          frames=4)
    with pytest.raises(ValueError, match=r"^IntrinsicReward step 4: key 'observation\[2, 1, 0\]': expected a finite"):
        run(env, 10)
    env = IntrinsicReward(Scripted(space, lambda t, rng: image(t, rng)[:, :4]), "vta.surprise", frames=4)
    with pytest.raises(ValueError, match=r"^IntrinsicReward reset: key 'observation': expected an array of shape "
                                         r"\(6, 5, 3\).*got an array of shape \(6, 4, 3\)$"):
        env.reset(seed=0)


def test_out_of_bounds_values_are_clipped_and_counted_in_info():
    """Finite values outside a Box's bounds (environments emit them: CartPole's velocities are
    unbounded in fact) are clipped to the bounds in the frame and counted in
    ``info["observation_out_of_bounds"]``: the count novelty bonus is that of the clipped cell."""
    space = gym.spaces.Box(np.array([0.0, -1.0], np.float32), np.array([1.0, 1.0], np.float32))
    env = IntrinsicReward(Scripted(space, lambda t, rng: rng.uniform(-1.5, 2.5, 2)), "vta.novelty", scale=0.5)
    obs, info = env.reset(seed=1)
    assert info["observation_out_of_bounds"] == int(np.sum((obs < space.low) | (obs > space.high)))
    counts, outside = {}, 0
    for _ in range(300):
        obs, _, _, _, info = env.step(0)
        n = int(np.sum((obs < space.low) | (obs > space.high)))
        assert info["observation_out_of_bounds"] == n
        outside += n
        cell = np.minimum((np.clip((obs - space.low) / (space.high - space.low), 0, 1) * 8).astype(int), 7)
        key = int(cell[0] + 8 * cell[1])
        counts[key] = counts.get(key, 0) + 1
        assert info["intrinsic_reward"] == pytest.approx(0.5 / np.sqrt(counts[key]), rel=1e-12)
    assert outside > 100 and counts[0] > 10  # corners hold the clipped values


def test_the_vector_wrapper_checks_each_sub_environment_and_counts_out_of_bounds_values():
    space = gym.spaces.Box(-1.0, 1.0, (2,), np.float64)
    envs = gym.vector.SyncVectorEnv([lambda: Scripted(space, lambda t, rng: rng.uniform(-2, 2, 2))] * 2
                                    + [lambda: Scripted(space, spoiled(6, with_value(1, np.nan), space))])
    wrapped = IntrinsicRewardVector(envs, "vta.novelty")
    wrapped.reset(seed=3)
    for _ in range(5):
        obs, _, _, _, info = wrapped.step(np.zeros(3, dtype=int))
        np.testing.assert_array_equal(info["observation_out_of_bounds"], np.sum(np.abs(obs) > 1, axis=1))
    with pytest.raises(ValueError, match=r"^IntrinsicRewardVector step 6 of sub-environment 2: key "
                                         r"'observation\[1\]': expected a finite number"):
        wrapped.step(np.zeros(3, dtype=int))


@pytest.mark.parametrize("low, high", [(-1e308, 1e308), ([0.0, -1e308], [1.0, 1e308]), (-np.finfo(np.float64).max, np.finfo(np.float64).max)])
@pytest.mark.parametrize("model", ["vta.novelty", "vta.learning_progress"])
def test_bounds_too_wide_for_the_coder_are_refused_at_construction(low, high, model):
    space = gym.spaces.Box(np.zeros(2) + low, np.zeros(2) + high, dtype=np.float64)
    with pytest.raises(ConfigError, match=r"^IntrinsicReward: key 'observation_space': expected bounds whose width "
                                          r"high - low is a finite float64 in every dimension.*, got Box"):
        IntrinsicReward(Scripted(space, uniform(space)), model)


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
