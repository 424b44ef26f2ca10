"""Experiment files: loading, conditions, --set, seeds, one run, resolved config."""

import math
import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from neurocur.config import ConfigError
from neurocur.contexts.sources import paper_source
from neurocur.experiments import load_experiment, parse_set, run_one
from neurocur.results import dumps_toml, first_difference

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"
CIRCUIT = ROOT / "neurocur" / "circuits" / "cd_misfa.toml"


def write(tmp_path, text, name="exp.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).replace("CIRCUIT", str(CIRCUIT)))
    return path


def test_synthetic_experiment_has_the_papers_parameters():
    exp = load_experiment(SYNTHETIC)
    assert (exp.name, exp.runs, exp.steps) == ("synthetic", 25, 350_000)
    assert list(exp.conditions) == ["curious", "random_switching", "literal"]
    cur, rnd, lit = (exp.conditions[c] for c in ("curious", "random_switching", "literal"))
    circuits = ROOT / "neurocur" / "circuits"
    assert lit.circuit_path == CIRCUIT and rnd.circuit_path == circuits / "lesion_lc_random.toml"
    assert cur.circuit_path == circuits / "vta_state_progress.toml"  # the curious agent's reward (reproduction 2.8)
    paper = {"HPC.threshold": 0.3, "HPC.n_states": 1000, "HPC.max_clusters": 2, "EC.amnesic": 2.0, "EC.mca_rate": 0.05}
    chosen = {"HPC.clusterers": "state", "HPC.freeze": "converged", "HPC.drift_ratios": 2, "HPC.ordered": True,
              "HPC.reward_error": "episode", "HPC.min_spread": 0.2, "sensory.episodes_on_engage": 2, "EC.n_pca": 3}
    assert rnd.params == paper | chosen and cur.params == paper | chosen | {"PFC.alpha": "sample_average"}
    assert lit.params == paper | chosen | {"HPC.freeze": "episode_mean", "HPC.reward_error": "episode", "HPC.ordered": False,
                                            "HPC.min_spread": 0.0, "sensory.episodes_on_engage": 1,
                                            "EC.orthonormalize": 0}
    lc = cur.circuit.specs["LC"].params  # the circuit's defaults are the paper's epsilon-greedy
    assert (cur.circuit.specs["LC"].type_name, lc.epsilon0, lc.decay) == ("lc.epsilon_greedy", 0.6, 0.995)
    assert (lit.world["normalise"], lit.world["clock_offsets"]) == ("image", "zero")
    assert cur.world["contexts"] == ["S-A", "S-A", "S-B", "S-C", "S-D"]
    world = cur.make_world()
    assert world.n_states == 1000 and world.visit_length == 100 and world.frame_shape == (20, 20)
    spec = world.source_spec()
    assert spec.learnable == ("S-A", "S-B", "S-C") and spec.context_sources[4] == "S-D"
    # the lesion is part of the random condition's resolved circuit
    lesions = rnd.circuit.to_dict()["lesions"]
    assert lesions == [{"region": "LC", "how": "random"}]


def test_a_condition_lesions_its_circuit(tmp_path):
    path = tmp_path / "exp.toml"
    path.write_text(f'circuit = "{CIRCUIT}"\nruns = 1\nsteps = 10\n[conditions.a]\n'
                    'lesion = [{ region = "LC", how = "random" }]\n[conditions.b]\n')
    exp = load_experiment(path)
    assert exp.conditions["a"].circuit.lesions == (("LC", "random", {}),)
    assert exp.conditions["a"].circuit.specs["LC"].params.epsilon0 == 1.0
    assert exp.conditions["b"].circuit.lesions == ()


def test_a_condition_replaces_regions_and_adds_edges_as_a_variant_circuit_file_would(tmp_path):
    """Two variants combined in one condition, and a model whose new input the condition feeds."""
    from neurocur.circuit import Circuit

    path = write(tmp_path, """
        circuit = "cd_misfa"
        runs = 1
        steps = 10
        [conditions.combined]
        circuit = "vta_state_progress"
        replace.LC = { type = "lc.softmax", params = { gain = 3.0 } }
        params = { "LC.gain" = 5.0 }
        [conditions.slowness]
        replace.VTA = { type = "vta.slowness_progress", params = { boredom = -100.0 } }
        edges = [{ from = "EC", signal = "slowness_progress", to = "VTA", input = "progress" }]
        """)
    exp = load_experiment(path)
    combined = exp.conditions["combined"].circuit
    assert combined.specs["VTA"].type_name == "vta.state_progress" and combined.specs["LC"].type_name == "lc.softmax"
    assert combined.specs["LC"].params.gain == 5.0  # the condition's params apply after its replacement
    expected = Circuit.from_toml("vta_state_progress").replace("LC", {"type": "lc.softmax"}).with_params({"LC.gain": 5.0})
    assert combined.to_dict() == expected.to_dict()
    slowness, shipped = exp.conditions["slowness"].circuit.to_dict(), Circuit.from_toml("vta_slowness_progress").to_dict()
    assert slowness["regions"] == shipped["regions"]
    assert sorted(map(str, slowness["edges"])) == sorted(map(str, shipped["edges"]))


def test_runs_steps_and_sets_override_the_file():
    exp = load_experiment(SYNTHETIC, runs=3, steps=500, sets=[
        "HPC.threshold=0.25", "world.normalise=image", "params.LC.decay=0.9", "seed=7",
        "world.clock_offsets=[0, 0, 0, 0, 0]"])
    assert (exp.runs, exp.steps, exp.seed) == (3, 500, 7)
    for cond in exp.conditions.values():
        assert cond.params["HPC.threshold"] == 0.25 and cond.params["LC.decay"] == 0.9
        assert cond.world["normalise"] == "image" and cond.world["clock_offsets"] == [0] * 5
        assert cond.circuit.specs["HPC"].params.threshold == 0.25


def test_parse_set_reads_toml_literals():
    assert parse_set("a.b=0.3") == ("a.b", 0.3)
    assert parse_set("a.b = 3") == ("a.b", 3)
    assert parse_set("x=true") == ("x", True)
    assert parse_set("x=[1, 2]") == ("x", [1, 2])
    assert parse_set('x="two words"') == ("x", "two words")
    assert parse_set("x=image") == ("x", "image")  # a bare word is a string
    with pytest.raises(ConfigError, match="--set novalue: expected KEY=VALUE"):
        parse_set("novalue")


@pytest.mark.parametrize(
    "sets, message",
    [
        (["HPC.threshold=abc"], "--set HPC.threshold: expected a number > 0, got 'abc'"),
        (["HPC.nope=1"], "--set HPC.nope: expected a parameter of HPCParams"),
        (["XYZ.a=1"], "--set XYZ.a: expected 'REGION.param' with REGION one of"),
        (["world.normalise=foo"], "--set: key 'world.normalise': expected one of 'global', 'image', got 'foo'"),
        (["world.colour=1"], "--set: key 'world.colour': expected a parameter of SyntheticParams"),
        (["runs=0"], "--set runs: expected a positive integer, got 0"),
        (["steps=many"], "--set steps: expected a positive integer, got 'many'"),
        (["circuit=nowhere.toml"], "--set circuit: expected an existing circuit file"),
        (["threshold=0.3"], "--set threshold: expected runs, steps, seed, circuit"),
    ],
)
def test_bad_sets_name_the_key_and_the_expected_value(sets, message):
    with pytest.raises(ConfigError) as info:
        load_experiment(SYNTHETIC, sets=sets)
    assert message in str(info.value)


def test_unknown_condition_lists_the_known_ones():
    exp = load_experiment(SYNTHETIC)
    with pytest.raises(ConfigError, match="--condition lazy: expected one of curious, random_switching"):
        exp.select(["lazy"])
    assert [c.name for c in exp.select(["random_switching"])] == ["random_switching"]


@pytest.mark.parametrize(
    "body, key, expected",
    [
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\ncolour = 1', "colour", "one of the keys"),
        ('circuit = "CIRCUIT"\nsteps = 10', "runs", "a positive integer"),
        ('circuit = "missing.toml"\nruns = 1\nsteps = 10', "circuit", "an existing circuit file"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\nseed = -1', "seed", "an integer >= 0"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[params]\n"HPC.threshold" = "high"', "params.HPC.threshold",
         "a number > 0"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[params]\nthreshold = 0.3', "params.threshold", "'REGION.param'"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a.params]\n"LC.decay" = 2.0',
         "conditions.a.params.LC.decay", "a number > 0 and <= 1"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[world]\nvisit_length = 0', "world.visit_length",
         "an integer >= 1"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[world]\ncontexts = ["S-A", "S-X"]', "world.contexts",
         "source names among"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[world.sources]\nS-X = "nothere.npy"', "world.sources.S-X",
         "an existing .npy file"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[world.sources]\nS-X = "flat.npy"', "world.sources.S-X",
         "array of shape (n_steps, n_dims)"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[world.sources]\nS-X = "const.npy"', "world.sources.S-X",
         "non-constant"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nlesions = "LC"', "conditions.a.lesions",
         "one of the keys"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nlesion = "LC"', "conditions.a.lesion",
         "an array of lesion tables"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nlesion = [{ region = "XX", how = "random" }]',
         "conditions.a.lesion[0].region", "a declared region"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nlesion = [{ region = "LC", how = "random", level = 1 }]',
         "conditions.a.lesion[0].level", "no further keys"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nreplace.LC = { type = "lc.nothing" }',
         "conditions.a.replace.LC.type", "a registered region type"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nreplace.XX = { type = "lc.softmax" }',
         "conditions.a.replace.XX", "the name of a declared region"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nreplace.VTA = { type = "vta.slowness_progress" }',
         "conditions.a.replace.VTA", "an edge into its input 'progress'"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nedges = [{ from = "EC", signal = "nope", to = "VTA" }]',
         "conditions.a.edges[0].signal", "an output of region 'EC'"),
        ('circuit = "CIRCUIT"\nruns = 1\nsteps = 10\n[conditions.a]\nedges = "EC"',
         "conditions.a.edges", "an array of edge tables"),
    ],
)
def test_bad_files_name_the_file_and_key(tmp_path, body, key, expected):
    np.save(tmp_path / "flat.npy", np.arange(1000.0))
    np.save(tmp_path / "const.npy", np.ones((1000, 2)))
    path = write(tmp_path, body)
    with pytest.raises(ConfigError) as info:
        load_experiment(path)
    err = info.value
    assert (Path(err.source), err.key) == (path, key)
    assert expected in err.expected
    if "npy" in body:
        assert ".npy" in str(err)  # the message names the file


def test_user_sources_from_npy_files(tmp_path):
    (tmp_path / "data").mkdir()
    x = 3.0 * paper_source("S-B") + 1.0
    np.save(tmp_path / "data" / "x.npy", x)
    path = write(tmp_path, """
        circuit = "CIRCUIT"
        runs = 1
        steps = 100
        [world]
        contexts = ["S-X", "S-A", "S-D"]
        [world.sources]
        S-X = "data/x.npy"
        """)
    cond = load_experiment(path).conditions["default"]
    assert cond.world["sources"]["S-X"] == str(tmp_path / "data" / "x.npy")
    world = cond.make_world()
    world.reset(seed=0)
    np.testing.assert_array_equal(world.source_signal("S-X"), x)
    assert world.source_of("C1") == "S-X" and world.context_frames("C1").shape == (1000, 400)
    assert world.source_spec().learnable == ("S-A", "S-X")


def test_seeds_pair_runs_across_conditions_and_do_not_depend_on_the_run_count():
    exp = load_experiment(SYNTHETIC)
    short = load_experiment(SYNTHETIC, runs=3)
    children = np.random.SeedSequence(2026).spawn(25)
    for i in (0, 2):
        assert exp.run_seed(i).spawn_key == short.run_seed(i).spawn_key == children[i].spawn_key == (i,)
        np.testing.assert_array_equal(exp.run_seed(i).generate_state(4), children[i].generate_state(4))
    # run i of both conditions sees the very same world (mixing, S-D, clock offsets)
    worlds = []
    for cond in exp.conditions.values():
        world = cond.make_world()
        cond.circuit.build(world, seed=exp.run_seed(1))
        worlds.append(world)
    for c in range(5):
        np.testing.assert_array_equal(worlds[0].context_frames(c), worlds[1].context_frames(c))
        assert worlds[0].clock(c) == worlds[1].clock(c)


class _Projector:
    """A stand-in module whose slowest output is a fixed projection of the frames."""

    def __init__(self, w):
        self.w = w

    def transform(self, X):
        return np.column_stack([X @ self.w, X[:, 0]])


def test_module_quality_is_abs_corr_with_the_slow_dimension():
    from neurocur.contexts.synthetic import SyntheticWorld

    world = SyntheticWorld(["S-A", "S-B"])
    world.reset(seed=0)
    frames, src = world.context_frames(0), world.source_signal("S-A")
    # the least-squares read-out of the slow dimension is a perfect module (global normalisation is affine)
    w, *_ = np.linalg.lstsq(frames - frames.mean(0), src[:, 0] - src[:, 0].mean(), rcond=None)
    w_fast, *_ = np.linalg.lstsq(frames - frames.mean(0), src[:, 1] - src[:, 1].mean(), rcond=None)
    library = [_Projector(-w), _Projector(w_fast), _Projector(np.zeros(400))]
    modules = pd.DataFrame({"module": [0, 1, 2], "context": [0, 0, 0], "step": [0, 0, 0]})
    sources, quality, columns, tables = world.module_report(library, modules)
    assert sources == ["S-A"] * 3 and columns == {} and tables == {}
    assert quality[0] == pytest.approx(1.0, abs=1e-9) and quality[1] < 0.1 and math.isnan(quality[2])


def test_run_one_tables():
    exp = load_experiment(SYNTHETIC, steps=30_000)
    cond = exp.conditions["literal"]  # the single-episode freeze stores modules early
    result = run_one(cond, 3, exp.steps, exp.run_seed(3))
    ep, mod = result.episodes, result.modules
    assert list(ep.columns[:2]) == ["condition", "run"] and list(mod.columns[:2]) == ["condition", "run"]
    assert (ep["condition"] == "literal").all() and (ep["run"] == 3).all()
    assert ep["n_frames"].sum() == result.summary["frames"] >= 30_000
    for col in ("module", "step", "episode", "context", "n_clusters", "source", "quality", "gates"):
        assert col in mod.columns
    assert len(mod) >= 1  # the literal reading stores several modules within 30 000 frames
    assert len(mod) == result.summary["n_modules"] and result.summary["order"] == mod["source"].tolist()
    for row in mod.itertuples():
        assert row.source == ("S-A", "S-A", "S-B", "S-C", "S-D")[row.context]
        gated = ep[(ep["episode"] > row.episode) & (ep["gating_module"] == row.module)]
        names = sorted({f"C{c + 1}" for c in gated["context"]})
        assert row.gates.split(",") == names if names else row.gates == ""
        assert 0.0 <= row.quality <= 1.0
    assert result.summary["seed"] == {"entropy": 2026, "spawn_key": [3]}
    assert result.summary["contexts"][4] == {"name": "C5", "source": "S-D"}


def test_resolved_config_round_trips_through_toml():
    exp = load_experiment(SYNTHETIC, runs=2, sets=["HPC.threshold=0.25"])
    resolved = exp.resolved()
    text = dumps_toml(resolved, header="a header\nof two lines")
    assert text.startswith("# a header\n# of two lines\n")
    back = tomllib.loads(text)
    assert first_difference(back, tomllib.loads(dumps_toml(back))) is None
    assert back["seeds"] == {"entropy": 2026, "spawn_key": "[run]"}  # run i: spawn key [i], however many runs
    assert back["neurocur_version"] == __import__("neurocur").__version__
    cond = back["conditions"]["random_switching"]
    assert cond["circuit"] == str(ROOT / "neurocur" / "circuits" / "lesion_lc_random.toml")
    assert cond["params"]["HPC.threshold"] == 0.25
    assert cond["resolved_circuit"]["regions"]["HPC"]["params"]["threshold"] == 0.25
    assert cond["resolved_circuit"]["lesions"] == [{"region": "LC", "how": "random"}]


def test_first_difference_names_the_key():
    a = {"x": 1, "t": {"y": [1, 2, {"z": 0.5}]}}
    assert first_difference(a, a) is None
    assert first_difference(a, {"x": 2, "t": a["t"]}) == "x"
    assert first_difference(a, {"x": 1, "t": {"y": [1, 2, {"z": 0.25}]}}) == "t.y[2].z"
    assert first_difference(a, {"x": 1}) == "t"
    assert first_difference({"v": float("nan")}, {"v": float("nan")}) is None
    assert first_difference([1], [1, 2]) == "(root)"


def test_a_runs_first_frames_do_not_depend_on_its_length():
    """A longer run extends the shorter one bit for bit, so one long run gives every shorter length
    (docs/reproduction.md, iCub "Longer runs"): nothing the circuit or world does depends on ``steps``."""
    exp = load_experiment(SYNTHETIC)
    cond = exp.conditions["literal"]  # stores modules early, so storage is compared too
    short = run_one(cond, 1, 15_000, exp.run_seed(1))
    long = run_one(cond, 1, 30_000, exp.run_seed(1))
    n = len(short.episodes)
    assert len(long.episodes) > n and len(short.modules) >= 1
    pd.testing.assert_frame_equal(long.episodes.iloc[:n].reset_index(drop=True), short.episodes, check_exact=True)
    stored = ["module", "step", "episode", "context", "n_clusters", "source"]  # quality and gates: end of run
    early = long.modules[long.modules["episode"] < n][stored].reset_index(drop=True)
    pd.testing.assert_frame_equal(early, short.modules[stored].reset_index(drop=True), check_exact=True)
