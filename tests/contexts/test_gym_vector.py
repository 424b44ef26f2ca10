"""The gym world of any gymnasium package: ids registered by importing a module (``imports``,
``module:id``), imported only when the world is built, and vector observations scaled to [0, 1]
(``observation = "vector"``). The environments are this folder's ``gym_vector_env`` (no rendering,
like neurogym's tasks)."""

from __future__ import annotations

import sys

import gymnasium
import numpy as np
import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.contexts import build_world, world_params
from neurocur.contexts.gym import GymParams, GymWorld
from neurocur.contexts.gym_frames import VectorScale

MODULE = "gym_vector_env"
WALK, UNBOUNDED, SHORT = "neurocur_test/Walk-v0", "neurocur_test/UnboundedWalk-v0", "neurocur_test/ShortWalk-v0"
UNDECLARED = "neurocur_test/Undeclared-v0"
LOW, HIGH = np.array([-2.0, 0.0, 0.0, 0.0]), np.array([2.0, 10.0, 4.0, 4.0])


@pytest.fixture
def unimported(monkeypatch):
    """The helper module not imported and its ids not registered (both restored afterwards)."""
    monkeypatch.delitem(sys.modules, MODULE, raising=False)
    for env_id in (WALK, UNBOUNDED, SHORT, UNDECLARED):
        monkeypatch.delitem(gymnasium.registry, env_id, raising=False)


def _vector(envs, **kwargs):
    return GymWorld(envs, imports=[MODULE], observation="vector", visit_length=40, n_states=6, **kwargs)


def _history(world, context):
    return np.array(world.envs[context].unwrapped.history)


# -- imports: when and what ---------------------------------------------------------------------


def test_imports_happen_when_the_world_is_built_not_when_its_table_is_read(unimported):
    table = {"type": "gym", "imports": [MODULE], "envs": [WALK], "observation": "vector"}
    cls, params = world_params(table)
    assert cls is GymWorld and params.imports == (MODULE,)
    assert MODULE not in sys.modules and WALK not in gymnasium.registry
    world = build_world(table)
    assert MODULE in sys.modules and WALK in gymnasium.registry
    assert world.context_names == (WALK,) and world.frame_shape == (1, 4)


def test_gymnasiums_module_colon_id_form(unimported):
    world = GymWorld([f"{MODULE}:{WALK}", WALK], observation="vector", visit_length=5)
    assert MODULE in sys.modules
    assert world.context_names == (f"{MODULE}:{WALK}", WALK) and world.source_names == world.context_names
    assert world.envs[0].spec.id == WALK


@pytest.mark.parametrize("key, value, match", [
    ("imports", ["os; import shutil"], r"key 'imports\[0\]': expected a module name \(dotted Python identifiers"),
    ("imports", ["..relative"], r"key 'imports\[0\]': expected a module name"),
    ("imports", ["class"], r"key 'imports\[0\]': expected a module name"),
    ("envs", ["no such:Thing-v0"], r"key 'envs\[0\]': expected a gymnasium environment id, or 'module:id'"),
    ("envs", [f"{MODULE}:"], r"key 'envs\[0\]': expected a gymnasium environment id, or 'module:id'"),
    ("envs", [WALK], r"key 'envs\[0\]': expected a registered gymnasium environment id .* or the module that "
                     r"registers it in imports"),
])
def test_names_that_are_not_modules_are_refused_before_any_import(unimported, key, value, match):
    table = {"envs": [WALK], "imports": None, key: value}
    modules = set(sys.modules)
    with pytest.raises(ConfigError, match=match):
        GymParams(**table)
    assert set(sys.modules) == modules


def test_a_failing_import_is_one_line_naming_the_key(unimported, tmp_path, monkeypatch):
    with pytest.raises(ConfigError, match=r"^GymParams: key 'imports\[1\]': expected a module that imports "
                                          r"\(installed, or on PYTHONPATH\), got 'no_such_module_x', whose import "
                                          r"raised ModuleNotFoundError: No module named 'no_such_module_x'$"):
        GymWorld(["CartPole-v1"], imports=[MODULE, "no_such_module_x"])
    (tmp_path / "broken_envs.py").write_text("raise RuntimeError('no licence\\nsecond line')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ConfigError) as info:
        GymWorld(["broken_envs:Broken-v0"], observation="vector")
    assert str(info.value) == ("GymParams: key 'envs[0]': expected a module that imports (installed, or on "
                               "PYTHONPATH), got 'broken_envs', whose import raised RuntimeError: no licence")
    with pytest.raises(ConfigError, match=r"key 'envs\[1\]': expected a registered gymnasium environment id "
                                          r"\(e.g. 'CartPole-v1'\) once 'gym_vector_env' is imported, got "
                                          r"'neurocur_test/Nothing-v0'"):
        _vector([WALK, "neurocur_test/Nothing-v0"])


def test_a_world_that_renders_refuses_an_env_without_rgb_array_and_names_vector(unimported):
    with pytest.raises(ConfigError, match=r"key 'envs\[0\]': expected an environment that renders rgb_array frames "
                                          r"\(its render modes: \[\]\); for its observation vectors, observation = "
                                          r"'vector', got 'neurocur_test/Walk-v0'"):
        GymWorld([WALK], imports=[MODULE])
    with pytest.raises(ConfigError, match=r"key 'envs\[1\]': expected an environment that renders rgb_array frames "
                                          r"\(its render modes: \[\]\)"):
        GymWorld(["CartPole-v1", UNDECLARED], imports=[MODULE])  # metadata without render_modes: none


# -- vector observations ------------------------------------------------------------------------


def test_vector_frames_are_the_observations_scaled_by_the_space_bounds():
    world = _vector([WALK, WALK], max_episode_steps=12)
    ep, _ = world.reset(seed=3, context=0)
    raw = _history(world, 0)
    assert ep.frames.shape == (40, 4) and raw.shape == (40, 4)
    np.testing.assert_array_equal(ep.frames, (raw - LOW) / (HIGH - LOW))  # the bounds of the space, no clipping
    assert ep.frames.min() >= 0.0 and ep.frames.max() <= 1.0 and len(ep.starts) > 1  # episodes ended inside
    np.testing.assert_array_equal(ep.states, np.minimum(raw[:, 1], 5))  # the step in the episode, capped
    np.testing.assert_array_equal(ep.frames[ep.starts, 1], 0.0)
    again = _vector([WALK, WALK], max_episode_steps=12)
    np.testing.assert_array_equal(again.reset(seed=3, context=0)[0].frames, ep.frames)
    assert not np.array_equal(_vector([WALK, WALK]).reset(seed=4, context=0)[0].frames, ep.frames)


def test_unbounded_dimensions_take_the_declared_range_and_clip():
    world = _vector([UNBOUNDED], observation_range=[-1.0, 3.0])
    ep, _ = world.reset(seed=0)
    raw = _history(world, 0)
    expected = np.clip((raw + 1.0) / 4.0, 0.0, 1.0)
    np.testing.assert_array_equal(ep.frames, expected)
    assert (raw[:, 0] < -1.0).any() and (ep.frames == 0.0).any()  # clipped below
    assert (raw[:, 1] > 3.0).any() and (ep.frames == 1.0).any()  # and above
    with pytest.raises(ConfigError, match=r"key 'observation_range': expected \[low, high\] for the 4 unbounded "
                                          r"dimension\(s\) of the observation of 'neurocur_test/UnboundedWalk-v0'"):
        _vector([UNBOUNDED])


def test_float32s_largest_value_counts_as_unbounded():
    """Environments bound an unbounded dimension by float32's largest value (gymnasium's CartPole did before
    1.0): scaled by it, the dimension would be 0.5 always."""
    big = np.finfo(np.float32).max
    space = gymnasium.spaces.Box(np.array([-1.0, -big, 0.0], dtype=np.float32), np.array([1.0, big, np.inf], dtype=np.float32))
    scale = VectorScale(space, (-4.0, 4.0), where="GymParams", env="a")
    obs = np.array([0.5, 1.0, 6.0], dtype=np.float32)
    np.testing.assert_allclose(scale(obs), [0.75, 5.0 / 8.0, 1.0])  # a finite low is kept: (6 - 0) / (4 - 0), clipped
    np.testing.assert_allclose(scale(np.array([-1.0, -8.0, 2.0], dtype=np.float32)), [0.0, 0.0, 0.5])
    with pytest.raises(ValueError, match=r"'a' returned a non-finite observation: \[0.5, nan, 1.0\]"):
        scale(np.array([0.5, np.nan, 1.0], dtype=np.float32))
    with pytest.raises(ConfigError, match=r"key 'observation_range': expected a range whose low is below every finite"):
        VectorScale(space, (-4.0, -1.0), where="GymParams", env="a")  # the third dimension: [0, -1]
    constant = VectorScale(gymnasium.spaces.Box(np.array([0.0, 2.0]), np.array([1.0, 2.0]), dtype=np.float64), None,
                           where="GymParams", env="c")
    np.testing.assert_array_equal(constant(np.array([0.25, 2.0])), [0.25, 0.0])
    onehot = VectorScale(gymnasium.spaces.Discrete(3), None, where="GymParams", env="d")
    np.testing.assert_array_equal(onehot(2), [0.0, 0.0, 1.0])


def test_a_gymnasium_env_as_vectors_scales_infinite_bounds_by_the_declared_range():
    world = GymWorld(["CartPole-v1"], observation="vector", observation_range=[-2.0, 2.0], visit_length=30)
    ep, _ = world.reset(seed=1)
    high = world.envs[0].observation_space.high  # finite: position and angle; infinite: the velocities
    assert np.isfinite(high[[0, 2]]).all() and not np.isfinite(high[[1, 3]]).any() and ep.frames.shape == (30, 4)
    assert ep.frames[:, 1].std() > 0.01 and ep.frames[:, 3].std() > 0.01
    x, v, theta, omega = world._observations[0]  # the last row's observation
    np.testing.assert_allclose(ep.frames[-1], [(x + high[0]) / (2 * high[0]), np.clip((v + 2) / 4, 0, 1),
                                               (theta + high[2]) / (2 * high[2]), np.clip((omega + 2) / 4, 0, 1)])
    with pytest.raises(ConfigError, match=r"2 unbounded dimension\(s\) of the observation of 'CartPole-v1' \(of 4\)"):
        GymWorld(["CartPole-v1"], observation="vector")


def test_vector_parameters_are_checked():
    with pytest.raises(ConfigError, match=r"key 'observation': expected one of 'render', 'vector'"):
        GymParams(envs=("CartPole-v1",), observation="pixels")
    with pytest.raises(ConfigError, match=r"key 'observation_range': expected \[low, high\] with low < high"):
        GymParams(envs=("CartPole-v1",), observation="vector", observation_range=(1.0, 1.0))
    with pytest.raises(ConfigError, match=r"key 'observation_range': expected no range unless observation = 'vector'"):
        GymParams(envs=("CartPole-v1",), observation_range=(0.0, 1.0))
    with pytest.raises(ValueError, match=r"observations of one size in every environment; got sizes "
                                         r"\{'neurocur_test/Walk-v0': 4, 'neurocur_test/ShortWalk-v0': 3\}"):
        _vector([WALK, SHORT])


def test_vector_world_as_env_passes_check_env(check_env_strictly):
    env = _vector([WALK]).as_env()
    check_env_strictly(env)
    obs, _ = env.reset(seed=0)
    assert obs["frames"].shape == (40, 4)


# -- end to end ---------------------------------------------------------------------------------

EXPERIMENT = f"""
name = "walks"
circuit = "cd_misfa"
runs = 2
steps = 100000

[world]
type = "gym"
imports = ["{MODULE}"]
envs = ["{WALK}", "{MODULE}:{UNBOUNDED}"]
observation = "vector"
observation_range = [-2.0, 2.0]
visit_length = 25
n_states = 10

[params]
"HPC.n_states" = 10
"""


def test_an_experiment_file_of_a_vector_world_runs_and_writes_results(tmp_path, capsys):
    path, out = tmp_path / "walks.toml", tmp_path / "out"
    path.write_text(EXPERIMENT)
    rc = main(["run", str(path), "--runs", "1", "--steps", "500", "--jobs", "1", "--out", str(out), "--no-progress"])
    assert rc == 0, capsys.readouterr().err
    episodes = pd.read_parquet(out / "runs" / "default" / "run-000" / "episodes.parquet")
    assert episodes["n_frames"].sum() >= 500 and set(episodes["context"]) <= {0, 1}
    assert (out / "summary.json").is_file()


@pytest.mark.parametrize("imports, message", [
    ('["gym vector"]', "walks.toml: key 'world.imports[0]': expected a module name (dotted Python identifiers, "
                       "e.g. 'neurogym'), got 'gym vector' (str)"),
    ('["no_such_module_x"]', "walks.toml: key 'world.imports[0]': expected a module that imports "
                             "(installed, or on PYTHONPATH), got 'no_such_module_x', whose import raised "
                             "ModuleNotFoundError: No module named 'no_such_module_x' (condition 'default')"),
])
def test_an_experiment_file_whose_module_does_not_import_exits_2_with_one_line(imports, message, tmp_path, capsys):
    path, out = tmp_path / "walks.toml", tmp_path / "out"
    path.write_text(EXPERIMENT.replace(f'imports = ["{MODULE}"]', f"imports = {imports}"))
    rc = main(["run", str(path), "--runs", "1", "--steps", "300", "--jobs", "1", "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and err.splitlines() == [f"neurocur run: error: {message}".replace("walks.toml", str(path))]
    assert not (out / "runs").exists()
