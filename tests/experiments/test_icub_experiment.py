"""The iCub experiment (section 4.2): world table, source spec, module report, run + figures end to end."""

import json
import math
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.figures.icub import fig_module_error
from neurocur.analysis.stats.icub import ICUB, learning_segments
from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.contexts import build_world
from neurocur.contexts.base import Episode
from neurocur.contexts.icub import REFERENCE_EPISODES, ICubWorld
from neurocur.experiments import load_experiment

ROOT = Path(__file__).resolve().parents[2]
ICUB_TOML = ROOT / "neurocur" / "experiments_data" / "icub.toml"
CIRCUIT = ROOT / "neurocur" / "circuits" / "cd_misfa.toml"


def _gl_available() -> bool:
    """Whether MuJoCo can render offscreen here (the iCub data set needs it)."""
    try:
        from neurocur.contexts.icub_data import _mujoco

        mj = _mujoco()
        model = mj.MjModel.from_xml_string("<mujoco><worldbody><geom type='sphere' size='1'/></worldbody></mujoco>")
        renderer = mj.Renderer(model, 8, 8)
        renderer.update_scene(mj.MjData(model))
        renderer.render()
        renderer.close()
        return True
    except Exception:  # any import or GL failure means: no offscreen rendering
        return False


needs_gl = pytest.mark.skipif(not _gl_available(), reason="MuJoCo offscreen rendering unavailable")


def write(tmp_path, world: str) -> Path:
    path = tmp_path / "exp.toml"
    body = f'circuit = "{CIRCUIT}"\nruns = 1\nsteps = 10\n[world]\ntype = "icub"\n' + textwrap.dedent(world)
    path.write_text(body)
    return path


def test_icub_experiment_has_the_papers_parameters(tmp_path):
    exp = load_experiment(ICUB_TOML)
    assert exp.runs == 15 and set(exp.conditions) == {"curious", "random_switching"}
    p = exp.conditions["curious"].params
    assert p["sensory.episodes_on_engage"] == 2
    assert (p["HPC.n_states"], p["HPC.max_clusters"]) == (20, 3)
    assert p["HPC.threshold"] * p["HPC.n_states"] == pytest.approx(2.3)  # eq 11 summed over the 20 states
    assert (p["LC.epsilon0"], p["LC.decay"]) == (0.6, 0.93)
    assert (p["EC.amnesic"], p["EC.var_fraction"], p["EC.mca_rate"]) == (0.4, 0.98, 0.01)
    assert exp.conditions["random_switching"].circuit_path.name == "lesion_lc_random.toml"
    world = exp.conditions["curious"].world
    assert world["type"] == "icub" and world["n_episodes"] == 70


def test_loading_does_not_build_the_world(tmp_path):
    exp = load_experiment(ICUB_TOML, sets=[f"world.cache_dir={json.dumps(str(tmp_path / 'cache'))}"])
    assert exp.conditions["curious"].world_type == "icub"
    assert ICUB.context_names == ("topple", "roll") and ICUB.learnable == ("topple", "roll")
    assert not (tmp_path / "cache").exists()  # loading simulated nothing


@pytest.mark.parametrize("world, key, expected", [
    ("n_episodes = 0", "world.n_episodes", "an integer >= 1"),
    ("dataset_seed = -1", "world.dataset_seed", "an integer >= 0"),
    ("n_jobs = 1.5", "world.n_jobs", "an integer >= 1"),
    ("cache_dir = 3", "world.cache_dir", "a file or folder path"),
    ("visit_length = 100", "world.visit_length", "a parameter of ICubParams"),
    ("[world.protocol]\ncolour = 1", "world.protocol.colour", "a parameter of EpisodeParams"),
    ("[world.protocol]\nmin_frames = 10", "world.protocol.min_frames", "an integer >= 50 and <= 250"),
    ("[world.protocol]\nmin_frames = 200\nmax_frames = 100", "world.protocol.min_frames", "at most max_frames = 100"),
    ("[world.protocol]\npost_contact = 2.5", "world.protocol.post_contact", "an integer"),
    ("[world.scene]\nshoulder = [0.1, 0.2]", "world.scene.shoulder", "a list of 3 items, each a number"),
    ("[world.scene]\nn_states = 4\n[world.protocol]\nstart_state = 4", "world.protocol.start_state",
     "< scene.n_states = 4"),
    ("[world.scene]\nreach = \"far\"", "world.scene.reach", "a number"),
    ("[world.scene]\narm = \"mesh\"", "world.scene.arm", "one of 'primitive', 'icub'"),
])
def test_bad_icub_world_tables_name_the_file_and_key(tmp_path, world, key, expected):
    path = write(tmp_path, world)
    with pytest.raises(ConfigError) as info:
        load_experiment(path)
    assert (Path(info.value.source), info.value.key) == (path, key)
    assert expected in info.value.expected


def test_bad_icub_sets_name_the_key():
    with pytest.raises(ConfigError, match="--set: key 'world.n_episodes': expected an integer >= 1"):
        load_experiment(ICUB_TOML, sets=["world.n_episodes=0"])
    with pytest.raises(ConfigError, match="--set: key 'world.protocol.max_frames': expected an integer >= 50 and <= 250"):
        load_experiment(ICUB_TOML, sets=["world.protocol.max_frames=300"])


def test_cache_dir_is_relative_to_the_experiment_file(tmp_path):
    path = write(tmp_path, 'cache_dir = "data/icub"')
    world = load_experiment(path).conditions["default"].world
    assert world["cache_dir"] == str((tmp_path / "data" / "icub").resolve())


class _FakeWorld:
    """Two contexts of random frames with a known displacement; enough for ICubWorld.module_report."""

    n_contexts, n_episodes, source_names = 2, 4, ("topple", "roll")

    def __init__(self, rng):
        self.eps = {(c, i): (rng.random((20 + 5 * i, 6)), rng.integers(0, 20, 20 + 5 * i), rng.random(20 + 5 * i))
                    for c in range(2) for i in range(4)}

    def episode(self, c, i):
        frames, states, _ = self.eps[(c, i)]
        return Episode(frames=frames, states=states, context=c)

    def displacement(self, c, i):
        return self.eps[(c, i)][2]

    def contact_frame(self, c, i):
        return 3


class _Module:
    n_components = 2

    def __init__(self, rng):
        self.projection_ = rng.standard_normal((6, 2))
        self.mean_ = rng.random(6)


def test_module_report_correlations_against_numpy():
    rng = np.random.default_rng(0)
    world, library = _FakeWorld(rng), [_Module(rng), _Module(rng)]
    modules = pd.DataFrame({"module": [0, 1], "context": [0, 1]})
    sources, quality, columns, tables = ICubWorld.module_report(world, library, modules)
    assert sources == ["topple", "roll"]

    def pooled(c, f):
        return np.concatenate([f(c, i) for i in range(4)])

    frames = {c: pooled(c, lambda c, i: world.eps[(c, i)][0]) for c in range(2)}
    disp = {c: pooled(c, world.displacement) for c in range(2)}
    states = {c: pooled(c, lambda c, i: world.eps[(c, i)][1]) for c in range(2)}
    for m, (own, other) in enumerate(((0, 1), (1, 0))):
        y = {c: (frames[c] - library[m].mean_) @ library[m].projection_[:, 0] for c in range(2)}
        assert quality[m] == pytest.approx(abs(np.corrcoef(y[own], disp[own])[0, 1]), abs=1e-12)
        assert columns["arm_corr"][m] == pytest.approx(abs(np.corrcoef(y[own], states[own])[0, 1]), abs=1e-12)
        assert columns["other_quality"][m] == pytest.approx(abs(np.corrcoef(y[other], disp[other])[0, 1]), abs=1e-12)
        both = np.concatenate([y[0], y[1]])
        ctx = np.repeat([0.0, 1.0], [len(y[0]), len(y[1])])
        assert columns["context_corr"][m] == pytest.approx(abs(np.corrcoef(both, ctx)[0, 1]), abs=1e-12)
    feats = tables["features"]
    assert sorted(feats["episode_index"].unique()) == [i for i in REFERENCE_EPISODES if i < 4]
    row = feats[(feats["module"] == 1) & (feats["context"] == 0) & (feats["episode_index"] == 2)]
    ep = world.episode(0, 2)
    np.testing.assert_allclose(row["y1"], (ep.frames - library[1].mean_) @ library[1].projection_[:, 1])
    np.testing.assert_allclose(row["displacement"], world.displacement(0, 2))
    empty = ICubWorld.module_report(world, [], modules.iloc[:0])
    assert empty[:2] == ([], []) and empty[3]["features"].empty


def test_learning_segments_and_module_error_figure():
    episodes = pd.DataFrame({
        "condition": "curious", "run": 0, "episode": range(6), "step": [0, 100, 200, 300, 400, 500],
        "n_frames": 100, "context": [0, 0, 0, 1, 1, 1], "n_modules": [0, 0, 1, 1, 1, 2],
        "module_learned": [False, False, True, False, False, True],
        "error": [0.9, 0.5, 0.1, 0.8, math.nan, 0.1]})
    seg = learning_segments(episodes)
    assert seg["learning_module"].tolist() == [0, 0, 0, 1, 1, 1]
    assert seg["frames_in"].tolist() == [0, 100, 200, 0, 100, 200]
    fig = fig_module_error(episodes, 1, bin_frames=100, threshold=0.115)
    line = fig.axes[0].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), [0.8, 0.1])  # the NaN (familiar) episode is left out


@needs_gl
def test_run_and_figures_end_to_end(tmp_path, capsys):
    out, cache = tmp_path / "res", tmp_path / "cache"
    sets = [f"world.cache_dir={json.dumps(str(cache))}", "world.n_episodes=6", "world.n_jobs=1",
            "HPC.threshold=5.0", "HPC.freeze=episode_mean"]  # store a module at the first episode with an error
    # (six episodes per context do not reach all 20 arm states, which the paper's context-wide rule needs)
    rc = main(["run", str(ICUB_TOML), "--runs", "1", "--steps", "2500", "--jobs", "1", "--out", str(out),
               "--no-progress", "--set", *sets])
    printed = capsys.readouterr().out
    assert rc == 0 and "topple first" in printed and "roll second" in printed
    assert len(list(cache.glob("icub-*.npz"))) == 1
    files = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    runs = [f"runs/{c}/run-000/{n}" for c in ("curious", "random_switching")
            for n in ("episodes.parquet", "features.parquet", "modules.parquet", "run.json")]
    assert files == ["config.toml", *runs, "summary.json"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["spec"]["learnable"] == ["topple", "roll"]
    modules = pd.read_parquet(out / "runs/curious/run-000/modules.parquet")
    assert len(modules) >= 1
    for col in ("quality", "arm_corr", "other_quality", "context_corr"):
        assert modules[col].between(0.0, 1.0).all()
    features = pd.read_parquet(out / "runs/curious/run-000/features.parquet")
    assert set(features["module"]) == set(modules["module"]) and set(features["context"]) == {0, 1}

    assert main(["figures", str(out)]) == 0
    printed = capsys.readouterr().out.split()
    names = {Path(line).name for line in printed if line.endswith(".png")}
    assert str(out / "figures" / "index.csv") in printed
    assert {"module_error_1.png", "module_error_2.png", "order_counts.png", "frames.png",
            "feature_output_curious.png", "reward_function_curious.png",
            "neuromodulators_random_switching.png"} <= names
    assert all((out / "figures" / n).stat().st_size > 1000 for n in names)
    world = build_world(load_experiment(ICUB_TOML, sets=sets[:2]).conditions["curious"].world)
    assert world.n_episodes == 6 and world.cache_path.parent == cache
