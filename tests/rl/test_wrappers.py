"""neurocur.rl's wrappers: gymnasium's checker, the spaces, determinism by seed, the bonus
recomputed independently of the wrapper, the vector version, third-party models and bad input."""

from __future__ import annotations

import dataclasses
import textwrap
import types
from importlib.metadata import EntryPoint

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from neurocur import registry
from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.contexts.base import Episode
from neurocur.regions import REGIONS
from neurocur.rl import IntrinsicReward, IntrinsicRewardVector
from neurocur.scheduler import region_seed

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def rollout(env, actions, seed):
    env.reset(seed=seed)
    out = []
    for a in actions:
        _, reward, terminated, truncated, info = env.step(a)
        out.append((reward, info["intrinsic_reward"], info["extrinsic_reward"]))
        if terminated or truncated:
            env.reset()
    return np.array(out)


@pytest.mark.parametrize("model", ["vta.learning_progress", "vta.novelty", "vta.surprise"])
def test_check_env_passes_and_spaces_are_the_environments(model):
    env = gym.make("CartPole-v1")
    wrapped = IntrinsicReward(env, model, frames=None if model == "vta.novelty" else 4)
    check_env(wrapped, skip_render_check=True)
    assert wrapped.observation_space is env.observation_space
    assert wrapped.action_space is env.action_space


def test_image_observations_pass_check_env():
    class Picture(gym.Env):
        observation_space = gym.spaces.Box(0, 255, (20, 24, 3), np.uint8)
        action_space = gym.spaces.Discrete(2)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            self.t = 0
            return self._obs(), {}

        def step(self, action):
            self.t += 1
            return self._obs(), 0.0, self.t >= 30, False, {}

        def _obs(self):
            return self.np_random.integers(0, 256, (20, 24, 3), dtype=np.uint8)

    wrapped = IntrinsicReward(Picture(), "vta.surprise", frames=4, image_size=8, hash_bits=1)
    check_env(wrapped, skip_render_check=True)
    coder = wrapped.sensory.coder
    assert coder.contexts == "simhash" and coder.n_pixels == 7 * 8  # every 3rd pixel: at most 8 a side
    picture = np.random.default_rng(0).integers(0, 256, (20, 24, 3), dtype=np.uint8)
    np.testing.assert_allclose(coder.frames(picture[None])[0], picture[::3, ::3].mean(axis=2).ravel() / 255.0)
    bonuses = rollout(wrapped, [0] * 80, seed=2)[:, 1]
    assert np.count_nonzero(bonuses) > 0


def test_same_seed_same_rewards_and_a_seeded_reset_starts_the_memory_afresh():
    actions = np.random.default_rng(0).integers(0, 2, 120)
    a = rollout(IntrinsicReward(gym.make("CartPole-v1"), "vta.surprise", frames=4), actions, seed=7)
    wrapped = IntrinsicReward(gym.make("CartPole-v1"), "vta.surprise", frames=4)
    b = rollout(wrapped, actions, seed=7)
    again = rollout(wrapped, actions, seed=7)
    other = rollout(wrapped, actions, seed=8)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, again)
    assert np.count_nonzero(a[:, 1]) > 5 and not np.array_equal(a, other)
    np.testing.assert_array_equal(a[:, 0], a[:, 1] + a[:, 2])


def test_count_novelty_bonus_is_scale_over_root_visits_of_the_grid_cell():
    """``vta.novelty`` on MountainCar: the bonus of step t is ``scale * decay**t / sqrt(N)``, N the
    visits of the observation's cell of an 8 x 8 grid over the bounds, counted here by hand."""
    env = gym.make("MountainCar-v0")
    wrapped = IntrinsicReward(env, "vta.novelty", scale=0.5, decay=0.99, params={"scale": 2.0})
    obs, _ = wrapped.reset(seed=3)
    low, high = env.observation_space.low, env.observation_space.high
    counts: dict[int, int] = {}
    rng = np.random.default_rng(1)
    for t in range(150):
        obs, reward, _, _, info = wrapped.step(int(rng.integers(3)))
        cell = np.minimum(((obs - low) / (high - low) * 8).astype(int), 7)
        key = int(cell[0] + 8 * cell[1])
        counts[key] = counts.get(key, 0) + 1
        assert info["intrinsic_reward"] == pytest.approx(0.5 * 0.99**t * 2.0 / np.sqrt(counts[key]), rel=1e-12)
        assert info["extrinsic_reward"] == reward - info["intrinsic_reward"] == -1.0
    assert len(counts) > 1 and max(counts.values()) > 1


def _manual(model, observations, rewards, *, seed, frames, space):
    """The bonus of a rollout computed without the wrapper: frames and SimHash contexts by hand,
    EC and HPC as standalone regions stepped in the circuit's order, DA by the model's formula."""
    coder_seed, circuit_seed = np.random.SeedSequence(seed).spawn(2)
    projection = np.random.default_rng(coder_seed).standard_normal((space.shape[0], 2))
    specs = Circuit.from_toml("cd_misfa").specs
    world = types.SimpleNamespace(n_contexts=4, n_states=frames + 1, n_pixels=space.shape[0])
    ec = REGIONS.get("ec.incsfa")("EC", specs["EC"].params)
    hpc = REGIONS.get("hpc.roc")("HPC", dataclasses.replace(specs["HPC"].params, n_states=frames + 1))
    ec.wired, hpc.wired = frozenset({"features", "library_features"}), frozenset({"familiar", "module_learned",
                                                                                   "reward_error"})
    for region in (ec, hpc):
        region.bind(world)
        region.reset(np.random.default_rng(region_seed(circuit_seed, region.name)))
    low, high = space.low.astype(np.float64), space.high.astype(np.float64)
    frames_of = np.clip((np.asarray(observations, dtype=np.float64) - low) / (high - low), 0.0, 1.0)
    previous, bonus = np.full(4, np.nan), []
    for end in range(frames, len(observations), frames):
        block = frames_of[end - frames: end + 1]
        context = int((((block[-1] - 0.5) @ projection) > 0) @ [1, 2])
        episode = Episode(block, np.arange(frames + 1), context, np.zeros(1, dtype=np.int64),
                          float(sum(rewards[end - frames: end])))
        features, library, *_ = ec.step(episode)
        familiar, learned, error, *_ = hpc.step(episode, features, library)
        if model == "vta.surprise":
            da = 0.0 if familiar or np.isnan(error) else error
        else:
            da = -100.0 if familiar else (0.0 if np.isnan(previous[context] - error) else previous[context] - error)
            if not np.isnan(error):
                previous[context] = error
            if learned:
                previous[:] = np.nan
        bonus += [0.0] * (frames - 1) + [da]
        ec.learn(familiar, learned)
        hpc.learn()
    return np.array(bonus)


@pytest.mark.parametrize("model", ["vta.surprise", "vta.learning_progress"])
def test_slow_feature_bonus_is_the_models_output_recomputed_independently(model):
    env = gym.make("Acrobot-v1")
    wrapped = IntrinsicReward(env, model, scale=0.25, frames=5, contexts="simhash", hash_bits=2)
    obs, _ = wrapped.reset(seed=11)
    observations, rewards, bonus = [obs], [], []
    rng = np.random.default_rng(4)
    for _ in range(200):
        obs, _, terminated, truncated, info = wrapped.step(int(rng.integers(3)))
        assert not (terminated or truncated)
        observations.append(obs)
        rewards.append(info["extrinsic_reward"])
        bonus.append(info["intrinsic_reward"])
    expected = 0.25 * _manual(model, observations, rewards, seed=11, frames=5, space=env.observation_space)
    assert len(expected) == len(bonus) == 200
    np.testing.assert_allclose(bonus, expected, rtol=1e-12, atol=0)
    assert np.count_nonzero(expected) > 10  # the comparison is not between zeros
    episodes = wrapped.sensory.simulator.episodes()
    assert len(episodes) == 40 and episodes["n_modules"].iloc[-1] >= 0


def test_vector_wrapper_shares_one_count_memory_and_skips_the_autoreset_step():
    envs = gym.make_vec("CartPole-v1", num_envs=3, vectorization_mode="sync")
    wrapped = IntrinsicRewardVector(envs, "vta.novelty", contexts="simhash", hash_bits=3)
    obs, _ = wrapped.reset(seed=5)
    coder, counts = wrapped.sensory.coder, {}
    restart = np.zeros(3, dtype=bool)
    rng = np.random.default_rng(2)
    for _ in range(80):
        obs, reward, terminated, truncated, info = wrapped.step(rng.integers(0, 2, 3))
        for i in range(3):
            if restart[i]:
                assert info["intrinsic_reward"][i] == 0.0
                continue
            key = int(coder.contexts_of(coder.frames(obs[i][None]))[0])
            counts[key] = counts.get(key, 0) + 1
            assert info["intrinsic_reward"][i] == pytest.approx(1.0 / np.sqrt(counts[key]), rel=1e-12)
        np.testing.assert_array_equal(reward, info["intrinsic_reward"] + info["extrinsic_reward"])
        restart = terminated | truncated
    assert wrapped.single_observation_space is envs.single_observation_space


def test_vector_wrapper_slow_features_is_deterministic():
    def run():
        wrapped = IntrinsicRewardVector(gym.make_vec("CartPole-v1", num_envs=2), "vta.surprise", frames=4)
        wrapped.reset(seed=9)
        return np.array([wrapped.step(np.array([t % 2, 1 - t % 2]))[4]["intrinsic_reward"] for t in range(60)])

    a = run()
    np.testing.assert_array_equal(a, run())
    assert np.count_nonzero(a) > 5


def test_a_third_party_vta_model_from_the_entry_point_group(tmp_path, monkeypatch):
    (tmp_path / "neurocur_rl_plugin.py").write_text(textwrap.dedent("""
        from neurocur.regions.vta import VTARole

        class Doubled(VTARole):
            def dopamine(self, context, reward_error, familiar, module_learned, reward):
                return 2.0 * reward + context
    """))
    monkeypatch.syspath_prepend(str(tmp_path))
    ep = EntryPoint(name="plugin.doubled", value="neurocur_rl_plugin:Doubled", group=REGIONS.group)
    monkeypatch.setattr(registry, "entry_points", lambda group: [ep] if group == REGIONS.group else [])
    monkeypatch.delitem(REGIONS._types, "plugin.doubled", raising=False)
    wrapped = IntrinsicReward(gym.make("MountainCar-v0"), "plugin.doubled", path="counts", scale=0.5)
    obs, _ = wrapped.reset(seed=0)
    low, high = wrapped.observation_space.low, wrapped.observation_space.high
    for _ in range(20):
        obs, _, _, _, info = wrapped.step(2)
        cell = np.minimum(((obs - low) / (high - low) * 8).astype(int), 7)
        assert info["intrinsic_reward"] == 0.5 * (2.0 * -1.0 + cell[0] + 8 * cell[1])
    check_env(IntrinsicReward(gym.make("CartPole-v1"), "plugin.doubled", frames=4), skip_render_check=True)


def test_bad_input_is_a_one_line_error_naming_what_was_expected():
    with pytest.raises(ConfigError, match=r"observation_space.*a Box of rank 1.*got Discrete"):
        IntrinsicReward(gym.make("FrozenLake-v1"), "vta.novelty")
    with pytest.raises(ConfigError, match=r"'model'.*registered region type.*'vta.nope'"):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.nope")
    with pytest.raises(ConfigError, match=r"'model'.*a VTA model"):
        IntrinsicReward(gym.make("CartPole-v1"), "ec.incsfa")
    with pytest.raises(ConfigError, match=r"'EC.n_pca'.*at most the 2 values"):
        IntrinsicReward(gym.make("MountainCar-v0"), "vta.surprise", overrides={"EC.n_pca": 3})
    fitted = IntrinsicReward(gym.make("MountainCar-v0"), "vta.surprise", overrides={"EC.n_pca": None})  # min(3, 2)
    fitted.reset(seed=0)
    for _ in range(3):
        fitted.step(0)
    with pytest.raises(ConfigError, match=r"'frames'.*integer >= 4"):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.surprise", frames=2)
    with pytest.raises(ConfigError, match=r"'frames'.*1 on the 'counts' path"):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.novelty", frames=8)
    with pytest.raises(ConfigError, match=r"'contexts'.*'simhash'"):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.novelty", contexts="grid")
    with pytest.raises(ConfigError, match=r"'decay'.*in \(0, 1\]"):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.novelty", decay=1.5)
    with pytest.raises(ConfigError, match=r"'path'.*reads HPC.progress -> VTA.progress"):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.state_progress", path="counts")
    with pytest.raises(gym.error.ResetNeeded):
        IntrinsicReward(gym.make("CartPole-v1"), "vta.novelty").step(0)


def test_vector_wrapper_same_step_autoreset_counts_the_final_observation():
    from gymnasium.vector import AutoresetMode

    envs = gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="sync",
                        vector_kwargs={"autoreset_mode": AutoresetMode.SAME_STEP})
    wrapped = IntrinsicRewardVector(envs, "vta.novelty", contexts="simhash", hash_bits=3)
    wrapped.reset(seed=1)
    coder, counts, ends = wrapped.sensory.coder, {}, 0
    for t in range(120):
        obs, _, terminated, truncated, info = wrapped.step(np.array([t % 2, (t // 3) % 2]))
        for i in range(2):
            done = terminated[i] or truncated[i]
            last = info["final_obs"][i] if done else obs[i]
            key = int(coder.contexts_of(coder.frames(np.asarray(last)[None]))[0])
            counts[key] = counts.get(key, 0) + 1
            assert info["intrinsic_reward"][i] == pytest.approx(1.0 / np.sqrt(counts[key]), rel=1e-12)
            ends += done
    assert ends >= 2


def test_vector_wrapper_refuses_a_disabled_autoreset():
    from gymnasium.vector import AutoresetMode

    envs = gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="sync",
                        vector_kwargs={"autoreset_mode": AutoresetMode.DISABLED})
    with pytest.raises(ConfigError, match=r"autoreset_mode.*NEXT_STEP or SAME_STEP"):
        IntrinsicRewardVector(envs, "vta.novelty")


@pytest.mark.parametrize("env_id, contexts", [("MountainCar-v0", "grid"), ("CartPole-v1", "simhash"),
                                              ("Pendulum-v1", "grid")])
def test_one_observations_compiled_context_is_the_frames_context(env_id, contexts):
    """The count path codes one observation in a compiled pass (ObservationCoder.context_of): the same
    grid cell or SimHash code as contexts_of(frames(...)) on 2000 observations of the space, out-of-bounds
    ones included (the frame clips them)."""
    from neurocur.rl.observations import ObservationCoder

    space = gym.make(env_id).observation_space
    coder = ObservationCoder(space, contexts=contexts, hash_bits=10, rng=np.random.default_rng(4))
    rng = np.random.default_rng(5)
    width = np.where(np.isfinite(space.high - space.low), space.high - space.low, 10.0)
    centre = np.where(np.isfinite(space.low + space.high), (space.low + space.high) / 2, 0.0)
    observations = centre + width * rng.uniform(-0.7, 0.7, size=(2000, space.shape[0]))
    expected = coder.contexts_of(coder.frames(observations))
    assert [coder.context_of(o) for o in observations] == expected.tolist()
    assert len(set(expected.tolist())) > 10
