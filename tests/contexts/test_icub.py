"""The simulated iCub world: rendering, episode protocol, cache, context API, Ω helper."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import asdict

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.contexts import icub, icub_body, icub_data
from neurocur.contexts.base import concatenate_episodes
from neurocur.contexts.icub import EpisodeParams, ICubWorld, omega_episodes
from neurocur.contexts.icub_scene import OBJECTS, SceneParams, scene_xml
from neurocur.learn.omega import omega, omega_from_eigenvalues
from neurocur.learn.sfa_batch import whiten_batch

N_EPISODES = 6


def _rendering_available() -> tuple[bool, str]:
    try:
        mj = icub_data._mujoco()
        model = mj.MjModel.from_xml_string(
            "<mujoco><worldbody><geom type='sphere' size='1'/></worldbody></mujoco>"
        )
        renderer = mj.Renderer(model, 8, 8)
        renderer.update_scene(mj.MjData(model))
        renderer.render()
        renderer.close()
        return True, ""
    except Exception as exc:  # any import or GL failure means: no offscreen rendering here
        return False, f"MuJoCo offscreen rendering unavailable (MUJOCO_GL=egl/osmesa): {exc}"


_OK, _WHY = _rendering_available()
needs_gl = pytest.mark.skipif(not _OK, reason=_WHY)


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """Six episodes per context, generated in two worker processes."""
    return ICubWorld(n_episodes=N_EPISODES, seed=0, cache_dir=tmp_path_factory.mktemp("icub"), n_jobs=2)


def _final_directions(w, context):
    """Final displacement (m) and its direction (deg) of the object in every episode."""
    moves = np.array([w.object_positions(context, i)[-1, :2] - w.object_positions(context, i)[0, :2]
                      for i in range(w.n_episodes)])
    return np.linalg.norm(moves, axis=1), np.degrees(np.arctan2(moves[:, 1], moves[:, 0]))


@needs_gl
def test_generation_is_deterministic_and_independent_of_workers(world, tmp_path):
    again = ICubWorld(n_episodes=N_EPISODES, seed=0, cache_dir=tmp_path, n_jobs=1)
    for c in range(2):
        for i in range(N_EPISODES):
            a, b = world.episode(c, i), again.episode(c, i)
            assert a.frames.shape == b.frames.shape
            np.testing.assert_allclose(a.frames.mean(), b.frames.mean(), atol=1e-12)
            np.testing.assert_allclose(a.frames.std(), b.frames.std(), atol=1e-12)
            np.testing.assert_allclose(world.displacement(c, i), again.displacement(c, i), atol=1e-9)
            np.testing.assert_array_equal(a.states, b.states)
    other = ICubWorld(n_episodes=2, seed=1, cache_dir=tmp_path, n_jobs=1)
    assert not np.array_equal(other.episode(0, 0).states, world.episode(0, 0).states)


@needs_gl
def test_frames_states_and_lengths(world):
    p = EpisodeParams()
    for c in range(2):
        for i in range(N_EPISODES):
            ep = world.episode(c, i)
            T = len(ep.frames)
            assert ep.frames.shape == (T, 75 * 100) and ep.frames.dtype == np.float64
            assert 0.0 <= ep.frames.min() and ep.frames.max() <= 1.0 and ep.frames.std() > 0.05
            assert 50 <= T <= 250
            assert ep.states.dtype == np.int64 and ep.states.min() >= 0 and ep.states.max() <= 19
            assert ep.states[0] == p.start_state
            np.testing.assert_array_equal(np.abs(np.diff(ep.states)), 1)
            k = world.contact_frame(c, i)
            expected = 250 if k < 0 else min(max(k + 1 + p.post_contact, p.min_frames), p.max_frames)
            assert T == expected
            assert world.displacement(c, i).shape == (T,) and world.displacement(c, i)[0] == 0.0


@needs_gl
def test_contact_in_most_episodes_and_the_object_moves(world):
    for c in range(2):
        contact = np.array([world.contact_frame(c, i) >= 0 for i in range(N_EPISODES)])
        assert contact.mean() >= 0.8
        before = [world.displacement(c, i)[: world.contact_frame(c, i)].max() for i in range(N_EPISODES) if contact[i]]
        assert max(before) < 0.005  # nothing moves the object before the hand touches it
    dist, _ = _final_directions(world, 0)
    assert np.all(dist > 0.08)  # every cup toppled and lies ~11 cm away


@needs_gl
def test_topple_is_alike_and_roll_directions_vary(world):
    d_top, a_top = _final_directions(world, 0)
    d_roll, a_roll = _final_directions(world, 1)
    # measured with seed 0: topple direction sd 2.8 deg, distance sd 1.3 cm; roll 15.5 deg, 8.3 cm
    assert a_top.std() < 5.0 and d_top.std() < 0.02
    assert a_roll.std() > 10.0 and d_roll.std() > 0.05
    assert a_roll.std() > 3 * a_top.std() and d_roll.std() > 3 * d_top.std()
    # a fallen cup lies (its centre at the cup's radius above the table); the ball stays on the table
    z_top = np.array([world.object_positions(0, i)[-1, 2] for i in range(N_EPISODES)])
    np.testing.assert_allclose(z_top, world.scene.cup_radius, atol=0.005)


@needs_gl
def test_second_construction_reads_the_cache(world, monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("episodes were simulated again instead of read from the cache")

    monkeypatch.setattr(icub, "_generate", boom)
    again = ICubWorld(n_episodes=N_EPISODES, seed=0, cache_dir=world.cache_path.parent)
    for c in range(2):
        np.testing.assert_array_equal(again.episode(c, 3).frames, world.episode(c, 3).frames)
    with pytest.raises(AssertionError, match="simulated again"):
        ICubWorld(n_episodes=N_EPISODES, seed=5, cache_dir=world.cache_path.parent)


@needs_gl
def test_reset_and_step_cycle_through_the_pool(world):
    assert world.context_names == ("topple", "roll") and world.source_names == ("topple", "roll")
    assert world.n_states == 20 and world.frame_shape == (75, 100) and world.n_pixels == 7500

    def draw(seed):
        ep, info = world.reset(seed=seed, context=1)
        order = [(1, info["episode_index"])]
        assert info["contact_frame"] == world.contact_frame(1, info["episode_index"])
        np.testing.assert_array_equal(ep.frames, world.episode(1, info["episode_index"]).frames)
        for c in [0] * 2 * N_EPISODES + [1] * (N_EPISODES - 1):
            ep, reward, term, trunc, info = world.step(c)
            assert (reward, term, trunc, ep.context) == (0.0, False, False, c)
            order.append((c, info["episode_index"]))
        return order

    order = draw(3)
    assert order == draw(3) and order != draw(4)
    topple = [i for c, i in order if c == 0]
    assert sorted(topple[:N_EPISODES]) == sorted(topple[N_EPISODES:]) == list(range(N_EPISODES))
    assert sorted(i for c, i in order if c == 1) == list(range(N_EPISODES))


@needs_gl
def test_visits_equal_steps_joined(world):
    """A stay's block (8-bit rows joined, then scaled once) is bit for bit the visits stepped one by
    one and joined: frames, states, starts, the pool order, ``last_info`` and the summed reward."""
    blocks, steps = (ICubWorld(n_episodes=N_EPISODES, seed=0, cache_dir=world.cache_path.parent,
                               rewards=[[1.0, 0.25, 2.0], 0.5]) for _ in range(2))
    blocks.reset(seed=5)
    steps.reset(seed=5)
    rng = np.random.default_rng(0)
    for _ in range(12):  # 1-4 visits, so the pool's order is used up and redrawn inside a block
        c, n = int(rng.integers(2)), int(rng.integers(1, 5))
        block = blocks.visits(c, n)
        joined = concatenate_episodes([steps.step(c)[0] for _ in range(n)])
        assert block.frames.dtype == np.float64 and block.frames.flags.c_contiguous
        np.testing.assert_array_equal(block.frames, joined.frames)
        np.testing.assert_array_equal(block.states, joined.states)
        np.testing.assert_array_equal(block.starts, joined.starts)
        assert (block.context, block.reward) == (joined.context, joined.reward)
        assert blocks.last_info == steps.last_info


@needs_gl
def test_as_env_passes_gymnasium_check_env(world, check_env_strictly):
    env = world.as_env()
    assert env.observation_space["frames"].shape == (250, 7500)
    check_env_strictly(env)
    obs, info = env.reset(seed=2, options={"context": 1})
    n = len(world.episode(1, info["episode_index"]).frames)
    assert obs["n_frames"] == n and info["contact_frame"] == world.contact_frame(1, info["episode_index"])


@needs_gl
def test_bad_arguments_raise(world, tmp_path):
    with pytest.raises(ValueError, match="context"):
        world.step(2)
    with pytest.raises(ValueError, match="episode_index"):
        world.displacement(0, N_EPISODES)
    with pytest.raises(ValueError, match="min_frames"):
        EpisodeParams(min_frames=20)
    with pytest.raises(ValueError, match="n_episodes"):
        ICubWorld(n_episodes=0, cache_dir=tmp_path)
    with pytest.raises(ValueError, match="seed"):
        ICubWorld(n_episodes=2, seed=-1, cache_dir=tmp_path)


def test_blurred_pools_are_the_gaussian_filter_rounded_to_8_bits():
    rng = np.random.default_rng(0)
    frames = np.zeros((3, 75, 100), np.uint8)
    frames[0, 30, 40] = 255  # a point: its blur is the kernel, symmetric, summing to the point
    frames[1] = 90  # flat: unchanged at every pixel (the border repeats)
    frames[2] = rng.integers(0, 256, (75, 100))
    pool = icub_data.EpisodePool(frames, np.arange(3), np.zeros((3, 3)), np.array([0, 3]), np.array([-1]))
    out = icub_data.blurred({"topple": pool}, 2.0, chunk=2)["topple"]
    assert out.frames.dtype == np.uint8 and out.states is pool.states
    point = out.frames[0].astype(float)
    assert point.argmax() == 30 * 100 + 40 and abs(point.sum() - 255) < 60  # each pixel rounded
    np.testing.assert_array_equal(point[30, 40 - 3], point[30, 40 + 3])
    assert point[30, 40 + 3] > point[30, 40 + 6] == 0
    assert (out.frames[1] == 90).all()
    assert out.frames[2].std() < 0.3 * frames[2].std()  # white noise loses most of its variance


@needs_gl
def test_a_blurred_world_caches_its_own_data_set(world):
    blurred = ICubWorld(params=icub.ICubParams(n_episodes=N_EPISODES, dataset_seed=0,
                                               cache_dir=world.cache_path.parent, blur=1.5))
    assert blurred.cache_path.name == world.cache_path.name.replace(".npz", "-blur1.5.npz")
    assert blurred.cache_path.exists()
    sharp, soft = world.episode(0, 1).frames, blurred.episode(0, 1).frames
    assert sharp.shape == soft.shape and soft.std(axis=0).mean() < sharp.std(axis=0).mean()
    with pytest.raises(ValueError, match="blur"):
        icub.ICubParams(blur=-1.0)


def _sources(T, rng, D=6):
    t = np.arange(T)
    S = np.column_stack([np.sin(2 * np.pi * t / T), np.sin(2 * np.pi * 9 * t / T), rng.standard_normal((T, 2))])
    return S @ rng.standard_normal((4, D))


def test_omega_episodes_matches_omega_on_one_episode():
    X = _sources(600, np.random.default_rng(0))
    np.testing.assert_allclose(omega_episodes([X], 0.01, var_fraction=1.0), omega(X, 0.01), rtol=0, atol=1e-10)


def test_omega_episodes_never_differences_across_episodes():
    rng = np.random.default_rng(1)
    a, b = _sources(300, rng), _sources(300, rng) + 5.0  # a jump between the two episodes
    glued = omega_episodes([np.vstack([a, b])], 0.01, var_fraction=1.0)
    split = omega_episodes([a, b], 0.01, var_fraction=1.0)
    # reference: whiten the concatenation, difference inside each episode only
    Z, _, _ = whiten_batch(np.vstack([a, b]))
    dZ = np.vstack([np.diff(Z[:300], axis=0), np.diff(Z[300:], axis=0)])
    ref = omega_from_eigenvalues(np.linalg.eigvalsh(dZ.T @ dZ / len(dZ)), 0.01)
    np.testing.assert_allclose(split, ref, atol=1e-10)
    assert abs(glued - split) > 1e-6


def test_omega_episodes_pca_keeps_the_variance_fraction():
    rng = np.random.default_rng(2)
    X = rng.standard_normal((400, 3)) * [10.0, 3.0, 1.0] @ np.linalg.qr(rng.standard_normal((50, 50)))[0][:3]
    reduced = icub.pca_reduce([X[:200], X[200:]], 0.95)  # variances ~100, 9, 1: two keep > 95 %
    assert [r.shape for r in reduced] == [(200, 2), (200, 2)]
    with pytest.raises(ValueError, match="episodes"):
        omega_episodes([X[:1]])


def test_importing_neurocur_does_not_import_mujoco():
    code = "import sys, neurocur, neurocur.contexts.icub; assert 'mujoco' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


# ---------------------------------------------------------------- the iCub's own arm (SceneParams.arm)


def test_a_bad_arm_names_the_key_and_the_choices():
    with pytest.raises(ConfigError, match=r"key 'arm': expected one of 'primitive', 'icub', got 'mesh'"):
        SceneParams(arm="mesh")


def test_the_icub_arm_without_its_package_names_the_extra(monkeypatch):
    monkeypatch.setattr(icub_body, "available", lambda: False)
    with pytest.raises(ConfigError, match=r"key 'arm'.*pip install 'neurocur\[icub\]'"):
        SceneParams(arm="icub")
    assert SceneParams().arm == "primitive"  # the default needs no package


def test_the_default_arm_keeps_the_cache_key_it_had_before_the_option():
    scene = SceneParams()
    assert icub_data._scene_key(scene) == {k: v for k, v in asdict(scene).items() if k not in ("arm", "arm_contrast")}
    icub_key = icub_data._scene_key(SceneParams(arm="icub"))
    assert icub_key["arm"] == "icub" and "icub_models" in icub_key
    assert "mesh" not in scene_xml("topple") and "mesh" not in scene_xml("roll")


def test_the_icub_arm_scene_has_the_same_bodies_and_massless_contact_free_meshes():
    mj = icub_data._mujoco()
    for obj in OBJECTS:
        plain = mj.MjModel.from_xml_string(scene_xml(obj))
        model = mj.MjModel.from_xml_string(scene_xml(obj, SceneParams(arm="icub")))
        for name in ("body_mass", "body_inertia", "body_ipos", "body_iquat", "dof_M0", "jnt_range", "actuator_gainprm"):
            np.testing.assert_array_equal(getattr(model, name), getattr(plain, name), err_msg=name)
        meshes = model.geom_type == mj.mjtGeom.mjGEOM_MESH
        assert meshes.sum() == len(icub_body.PROXIMAL) + len(icub_body.DISTAL) == model.nmesh
        assert (model.geom_bodyid[meshes] == model.body("arm").id).all()
        assert (model.geom_contype[meshes] == 0).all() and (model.geom_conaffinity[meshes] == 0).all()
        # the primitive arm still collides as before, but is not drawn (the renderer draws groups 0-2)
        arm = (model.geom_bodyid == model.body("arm").id) & ~meshes
        np.testing.assert_array_equal(model.geom_contype[arm], plain.geom_contype[plain.geom_bodyid == plain.body("arm").id])
        assert (model.geom_group[arm] == 3).all() and (model.geom_group[meshes] == 1).all()


def test_the_icub_hand_spans_the_primitive_hand():
    p = SceneParams()
    tip, height = p.reach + 0.03 + p.hand_radius, p.hand_height - p.shoulder[2]
    where = icub_body.placement(tip, height)
    model = icub_body._model()
    R, t = where["parts"]["r_hand"]
    hand = t + where["scale"] * model["hand_vertices"] @ R.T
    assert hand[:, 0].max() == pytest.approx(tip) and hand[:, 0].min() < p.reach - 0.045  # from the wrist to the tip
    R, t = where["parts"]["r_forearm"]
    np.testing.assert_allclose(t + where["scale"] * R @ model["shoulder"], 0.0, atol=1e-12)  # the shoulder on the hinge
    np.testing.assert_allclose(t + where["scale"] * R @ model["wrist"], where["wrist"], atol=1e-3)
    assert 0.9 < where["scale"] < 1.2  # about the iCub's own size


@needs_gl
def test_the_icub_arm_moves_the_object_bit_for_bit_as_the_primitive_arm(tmp_path):
    plain = ICubWorld(n_episodes=1, seed=3, cache_dir=tmp_path, n_jobs=1)
    icub_arm = ICubWorld(n_episodes=1, seed=3, cache_dir=tmp_path, n_jobs=1, scene=SceneParams(arm="icub"))
    assert icub_arm.cache_path != plain.cache_path
    for c in range(2):
        assert plain.contact_frame(c, 0) == icub_arm.contact_frame(c, 0) >= 0
        assert np.array_equal(plain.object_positions(c, 0), icub_arm.object_positions(c, 0))
        a, b = plain.episode(c, 0), icub_arm.episode(c, 0)
        assert np.array_equal(a.states, b.states)
        changed = a.frames != b.frames
        assert 0.01 < changed.mean() < 0.5  # the arm's pixels, not the whole image


# ---------------------------------------------------------------- the input parameters of the declared search


def test_new_fields_at_their_defaults_keep_the_default_cache_key():
    scene, protocol = SceneParams(), EpisodeParams()
    assert icub_data._key_fields(protocol) == {k: v for k, v in asdict(protocol).items() if k != "steps_per_frame"}
    assert "arm_contrast" not in icub_data._scene_key(scene)
    key = icub_data.cache_key(scene, protocol, 70, 0)
    assert icub_data.cache_key(SceneParams(arm_contrast=0.5), protocol, 70, 0) != key
    assert icub_data.cache_key(scene, EpisodeParams(steps_per_frame=2), 70, 0) != key


def test_arm_contrast_moves_the_robots_colours_towards_the_tables():
    from neurocur.contexts.icub_scene import ROBOT_RGB, TABLE_RGB

    xml = scene_xml("topple", SceneParams(arm_contrast=0.25))
    for name, rgb in ROBOT_RGB.items():
        expected = [t + 0.25 * (c - t) for c, t in zip(rgb, TABLE_RGB)]
        line = next(s for s in xml.splitlines() if f'material name="{name}"' in s)
        got = [float(x) for x in line.split('rgba="')[1].split('"')[0].split()[:3]]
        np.testing.assert_allclose(got, expected, atol=1e-6)
    with pytest.raises(ConfigError, match="arm_contrast"):
        SceneParams(arm_contrast=1.5)


def _arm_frames(scene=None, protocol=None):
    """The frames and states of the first topple episode of a scene, before the hand touches the cup."""
    sim = icub_data._Simulation("topple", scene or SceneParams(), protocol or EpisodeParams())
    try:
        frames, states, _, contact = sim.play(np.random.default_rng(3))
    finally:
        sim.close()
    return frames[:contact].astype(float), states[:contact]


@needs_gl
def test_a_low_arm_contrast_shrinks_the_arms_change_in_the_frames():
    sharp, states = _arm_frames()
    faint, faint_states = _arm_frames(SceneParams(arm_contrast=0.3))
    np.testing.assert_array_equal(states, faint_states)  # the same walk: only the look differs
    change = [np.abs(np.diff(f, axis=0)).mean() for f in (sharp, faint)]
    assert 0.2 < change[1] / change[0] < 0.6  # the arm's pixel changes scale about with the contrast


@needs_gl
def test_steps_per_frame_takes_that_many_babbling_steps_between_frames():
    _, one = _arm_frames()
    _, two = _arm_frames(protocol=EpisodeParams(steps_per_frame=2))
    assert set(np.abs(np.diff(one))) == {1}
    assert set(np.abs(np.diff(two))) <= {0, 2} and 2 in set(np.abs(np.diff(two)))


@needs_gl
def test_omega_experiment_icub_prints_omega_and_the_pca_dimensions(tmp_path, capsys):
    from neurocur.cli import main

    sets = ["world.n_episodes=4", f"world.cache_dir={tmp_path}", "world.n_jobs=1"]
    assert main(["omega", "--experiment", "icub", "--eta", "0.01", "--set", *sets]) == 0
    lines = capsys.readouterr().out.splitlines()
    world = ICubWorld(n_episodes=4, seed=0, cache_dir=tmp_path)
    for c, (name, line) in enumerate(zip(OBJECTS, lines)):
        dims = icub.pca_reduce(world.episodes(c), 0.98)[0].shape[1]
        assert line.split()[:2] == [name, name]
        assert f"Omega = {omega_episodes(world.episodes(c), 0.01):.5f}" in line
        assert line.endswith(f"(PCA to 98 % of the variance: {dims} dims)")
