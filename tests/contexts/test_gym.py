"""Worlds and gymnasium: the gymnasium seeding of World.reset, World.as_env, the GymWorld adapter."""

from __future__ import annotations

from pathlib import Path

import gymnasium
import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.contexts import WORLDS, build_world
from neurocur.contexts.env import env_id
from neurocur.contexts.gym import GymParams, GymWorld
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.experiments import load_experiment, run_one

EXPERIMENT = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "gym_classic.toml"


def _small_synthetic():
    return SyntheticWorld(visit_length=30, frame_shape=(6, 5))


def _visits(world, seed, contexts):
    first, _ = world.reset(seed=seed, context=contexts[0])
    return [first] + [world.step(c)[0] for c in contexts[1:]]


# -- World.reset: gymnasium's seeding ---------------------------------------------------------


def test_same_seed_same_frames():
    a, b = _visits(_small_synthetic(), 5, [1, 2, 2, 4]), _visits(_small_synthetic(), 5, [1, 2, 2, 4])
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x.frames, y.frames)
    assert not np.array_equal(a[0].frames, _visits(_small_synthetic(), 6, [1])[0].frames)


def test_reset_without_a_seed_continues_the_stream():
    w = _small_synthetic()
    seeded, _ = w.reset(seed=5)
    rng = w.np_random
    after, _ = w.reset()
    assert w.np_random is rng  # not re-seeded
    assert not np.array_equal(after.frames, seeded.frames)  # a new run, drawn from the continuing stream
    w.reset(seed=5)
    again, _ = w.reset()
    np.testing.assert_array_equal(again.frames, after.frames)


def test_the_first_unseeded_reset_seeds_from_the_os():
    a, b = _small_synthetic(), _small_synthetic()
    assert not np.array_equal(a.reset()[0].frames, b.reset()[0].frames)


def test_reset_options_name_the_first_context():
    w = _small_synthetic()
    ep, info = w.reset(seed=1, options={"context": 2})
    assert ep.context == info["context"] == 2
    by_keyword, _ = w.reset(seed=1, context=2)
    np.testing.assert_array_equal(ep.frames, by_keyword.frames)
    assert w.reset(seed=1, options={})[0].context == 0
    with pytest.raises(ValueError, match="not both"):
        w.reset(options={"context": 1}, context=1)
    with pytest.raises(ValueError, match="only hold 'context'"):
        w.reset(options={"contxt": 1})
    with pytest.raises(ValueError, match="context must be"):
        w.reset(options={"context": 5})


# -- World.as_env -------------------------------------------------------------------------------


def test_synthetic_env_passes_check_env(check_env_strictly):
    check_env_strictly(_small_synthetic().as_env())


def test_env_observation_is_the_padded_visit():
    world = _small_synthetic()
    env = world.as_env(max_frames=40)
    obs, info = env.reset(seed=3, options={"context": 1})
    ref, _ = _small_synthetic().reset(seed=3, context=1)
    assert info == {"context": 1} and env.np_random is world.np_random and env.np_random_seed == 3
    assert obs["frames"].shape == (40, 30) and obs["n_frames"] == 30
    np.testing.assert_array_equal(obs["frames"][:30], ref.frames)
    np.testing.assert_array_equal(obs["states"][:30], ref.states)
    assert not obs["frames"][30:].any() and not obs["states"][30:].any()
    np.testing.assert_array_equal(np.flatnonzero(obs["starts"]), [0])
    obs, reward, terminated, truncated, info = env.step(4)
    assert (reward, terminated, truncated, info["context"]) == (0.0, False, False, 4)
    image = env.render()
    assert image.shape == (6, 5, 3) and image.dtype == np.uint8
    np.testing.assert_array_equal(image[:, :, 0], np.round(obs["frames"][29].reshape(6, 5) * 255))
    with pytest.raises(RuntimeError, match="max_frames"):
        world.as_env(max_frames=10).step(0)


# -- GymWorld ----------------------------------------------------------------------------------


def _pendulum(**kwargs):
    """Pendulum never terminates: with a 10-step limit its episodes are exactly 11 frames."""
    return GymWorld(["Pendulum-v1", "CartPole-v1"], visit_length=30, frame_shape=(8, 12), n_states=5,
                    max_episode_steps=10, **kwargs)


def test_gym_frames_states_and_starts():
    w = _pendulum()
    ep, _ = w.reset(seed=0, context=0)
    assert w.context_names == ("Pendulum-v1", "CartPole-v1") and w.n_pixels == 96
    assert ep.frames.shape == (30, 96) and ep.frames.dtype == np.float64 and ep.context == 0
    assert 0.0 <= ep.frames.min() and ep.frames.max() <= 1.0 and ep.frames.std() > 0.01
    np.testing.assert_array_equal(ep.starts, [0, 11, 22])  # a reset after each 10-step episode
    np.testing.assert_array_equal(ep.states, np.minimum(np.arange(30) % 11, 4))
    ep = w.step(0)[0]  # the third episode continues: 3 more steps, then resets at rows 3 and 14
    np.testing.assert_array_equal(ep.starts, [0, 3, 14, 25])
    np.testing.assert_array_equal(ep.states[:4], [4, 4, 4, 0])
    cart = w.step(1)[0]
    assert cart.context == 1 and cart.starts[0] == 0 and np.all(cart.states[cart.starts] == 0)


def test_gym_world_is_deterministic_for_a_seed():
    a, b = _visits(_pendulum(), 4, [0, 1, 1, 0]), _visits(_pendulum(), 4, [0, 1, 1, 0])
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x.frames, y.frames)
        np.testing.assert_array_equal(x.starts, y.starts)
    assert not np.array_equal(a[0].frames, _visits(_pendulum(), 5, [0])[0].frames)


def test_fixed_reset_seeds_repeat_the_first_frame():
    w = _pendulum(reset_seeds=[7, -1])
    ep, _ = w.reset(seed=0)
    firsts = ep.frames[ep.starts]
    np.testing.assert_array_equal(firsts, firsts[[0, 0, 0]])
    assert not np.array_equal(ep.frames[1], ep.frames[12])  # the random actions differ


def test_gym_env_passes_check_env(check_env_strictly):
    check_env_strictly(GymWorld(["CartPole-v1"], visit_length=8, frame_shape=(4, 6)).as_env())


def test_gym_params_are_checked():
    assert WORLDS.get("gym") is GymWorld
    with pytest.raises(ConfigError, match="envs\\[1\\]"):
        GymParams(envs=("CartPole-v1", "NoSuchEnv-v0"))
    with pytest.raises(ConfigError, match="reset_seeds"):
        GymParams(envs=("CartPole-v1",), reset_seeds=(1, 2))
    with pytest.raises(ConfigError, match="distinct"):
        GymParams(envs=("CartPole-v1", "CartPole-v1"), context_names=("a", "a"))
    world = build_world({"type": "gym", "envs": ["CartPole-v1", "CartPole-v1"], "visit_length": 5,
                         "reset_options": [{}, {"low": -0.01, "high": 0.01}]})
    assert world.context_names == ("CartPole-v1#1", "CartPole-v1#2")
    assert world.source_spec().learnable == ("CartPole-v1",)


def test_the_example_experiment_runs():
    exp = load_experiment(EXPERIMENT, runs=1, steps=300, sets=["world.visit_length=30", "world.frame_shape=[8, 8]"])
    (condition,) = exp.conditions.values()
    result = run_one(condition, 0, exp.steps, exp.run_seed(0))
    episodes = result.episodes
    assert episodes["n_frames"].sum() >= 300 and set(episodes["context"]) <= {0, 1, 2}


# -- registered gymnasium ids --------------------------------------------------------------------

SMALL = {  # a small world of each type, by its gymnasium id
    "neurocur/Synthetic-v0": dict(visit_length=30, frame_shape=(6, 5)),
    "neurocur/Gym-v0": dict(envs=["CartPole-v1"], visit_length=8, frame_shape=(4, 6)),
    "neurocur/Conditioning-v0": {},
    "neurocur/Vigilance-v0": {},
    "neurocur/Options-v0": dict(options=["left", "middle", "right"], p_reward=[0.2, 0.5, 0.8]),
    "neurocur/Posner-v0": {},
    "neurocur/RewardBlocks-v0": dict(contexts=["S-A", "S-B"], visit_length=5, frame_shape=[3, 3],
                                     blocks=[[1.0, 0.2], [0.0, 0.5]], block_visits=3),
}


def test_every_world_type_has_a_gymnasium_id():
    ids = {name: env_id(WORLDS.get(name)) for name in WORLDS.names()}
    assert ids["synthetic"] == "neurocur/Synthetic-v0" and ids["icub"] == "neurocur/ICub-v0"
    assert set(ids.values()) == set(SMALL) | {"neurocur/ICub-v0"}  # the iCub world simulates on build: not made here
    for name, env in ids.items():
        assert gymnasium.spec(env).kwargs == {"type": name}


@pytest.mark.parametrize("world_id", SMALL)
def test_gymnasium_make_of_a_world_id_passes_check_env(world_id, check_env_strictly):
    env = gymnasium.make(world_id, **SMALL[world_id])
    check_env_strictly(env.unwrapped)  # made by gymnasium.make: the render-mode checks run too
    assert env.spec.id == world_id and env.render_mode == "rgb_array"
    assert gymnasium.make(world_id, render_mode=None, **SMALL[world_id]).render_mode is None


def test_gymnasium_make_builds_the_world_of_the_parameters():
    made = gymnasium.make("neurocur/Synthetic-v0", max_frames=40, **SMALL["neurocur/Synthetic-v0"])
    own = _small_synthetic().as_env(max_frames=40)
    a, _ = made.reset(seed=3, options={"context": 2})
    b, _ = own.reset(seed=3, options={"context": 2})
    np.testing.assert_array_equal(a["frames"], b["frames"])
    assert a["frames"].shape == (40, 30)
    with pytest.raises(ConfigError, match="key 'world.visit_length'"):
        gymnasium.make("neurocur/Synthetic-v0", visit_length=0)
