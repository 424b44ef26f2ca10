"""Experiment files that extend another (``extends``): what is inherited, what is replaced,
and errors that name the file that wrote the key."""

import textwrap

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment

#: the hypothesis runs and sweeps whose conditions must run synthetic.toml's chosen reading
EXTENDING = ("lc_softmax", "inverted_u_ne", "noisy_tv", "goldilocks", "sweep_pfc", "dopamine_dose", "gating_boredom",
             "lc_models", "ne_plasticity", "fit_curiosity", "ach_gating")


def write(folder, name, text):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


def test_a_file_inherits_the_reading_and_states_its_own_conditions(tmp_path):
    path = write(tmp_path, "mine.toml", """
        extends = "synthetic"
        runs = 3
        [params]
        "HPC.threshold" = 0.2
        [world]
        contexts = ["S-A", "S-B", "S-D"]
        context_names = ["A", "B", "D"]
        [conditions.only]
        params = { "VTA.boredom" = 0.0 }
        """)
    base, mine = load_experiment("synthetic"), load_experiment(path)
    assert (mine.name, mine.description, mine.runs, mine.steps, mine.seed) == ("mine", "", 3, base.steps, base.seed)
    assert list(mine.conditions) == ["only"]
    cond, reading = mine.conditions["only"], base.conditions["random_switching"]  # [params] alone: no own params
    assert cond.params == reading.params | {"HPC.threshold": 0.2, "VTA.boredom": 0.0}
    assert cond.world == reading.world | {"contexts": ["S-A", "S-B", "S-D"], "context_names": ["A", "B", "D"]}
    assert cond.circuit.specs["HPC"].params.threshold == 0.2 and cond.circuit.specs["HPC"].params.ordered
    assert cond.make_world().context_names == ("A", "B", "D")


@pytest.mark.parametrize("name", EXTENDING)
def test_hypothesis_runs_share_the_synthetic_reading(name):
    """Every condition of a shipped hypothesis run has synthetic.toml's [params] underneath its own
    (its random-switching condition has no params of its own)."""
    reading = load_experiment("synthetic").conditions["random_switching"]
    for cond in load_experiment(name).conditions.values():
        assert cond.params.items() >= {k: v for k, v in reading.params.items() if k not in cond.sweep}.items(), cond.name
        hpc = cond.circuit.specs["HPC"].params
        assert (hpc.freeze, hpc.drift_ratios, hpc.ordered) == ("converged", 2, True), cond.name


def test_the_epsilon_greedy_condition_is_synthetics_curious_run_with_the_papers_reward():
    """Same circuit, world and seeds: lc_softmax's ε-greedy runs are synthetic.toml's curious runs with
    the paper's reward (cd_misfa's learning progress, α = 0.2), which the hypothesis runs keep."""
    curious = load_experiment("synthetic", sets=['circuit="cd_misfa"', "PFC.alpha=0.2"])
    mine = load_experiment("lc_softmax")
    a, b = curious.conditions["curious"], mine.conditions["epsilon_greedy"]
    assert a.circuit.to_dict() == b.circuit.to_dict() and a.world == b.world
    assert [curious.run_seed(i).spawn_key for i in range(3)] == [mine.run_seed(i).spawn_key for i in range(3)]
    assert curious.seed == mine.seed


def test_chains_sweeps_and_paths_relative_to_the_file_that_wrote_them(tmp_path):
    (tmp_path / "base").mkdir()
    np.save(tmp_path / "base" / "x.npy",
            np.column_stack([np.sin(np.linspace(0, 2 * np.pi, 1000)), np.cos(np.linspace(0, 40 * np.pi, 1000))]))
    write(tmp_path / "base", "base.toml", """
        circuit = "cd_misfa"
        runs = 2
        steps = 1000
        seed = 5
        [world]
        contexts = ["S-X", "S-D"]
        [world.sources]
        S-X = "x.npy"
        [sweep]
        "HPC.threshold" = [0.1, 0.2]
        """)
    write(tmp_path / "mid", "mid.toml", """
        extends = "../base/base.toml"
        steps = 2000
        """)
    top = write(tmp_path / "top", "top.toml", """
        extends = "../mid/mid.toml"
        [sweep]
        "HPC.max_clusters" = [2, 3]
        """)
    exp = load_experiment(top)
    assert (exp.runs, exp.steps, exp.seed) == (2, 2000, 5)
    assert list(exp.conditions) == ["default@HPC.max_clusters=2", "default@HPC.max_clusters=3"]
    assert exp.conditions["default@HPC.max_clusters=2"].world["sources"]["S-X"] == str(tmp_path / "base" / "x.npy")


@pytest.mark.parametrize(("files", "source", "key", "expected"), [
    ({"a.toml": 'extends = "b.toml"', "b.toml": 'extends = "a.toml"'}, "b.toml", "extends", "without a loop"),
    ({"a.toml": 'extends = "nowhere"'}, "a.toml", "extends", "the name of a shipped experiment"),
    ({"a.toml": 'extends = "gone.toml"'}, "a.toml", "extends", "an existing experiment file"),
    ({"a.toml": 'extends = 3'}, "a.toml", "extends", "an experiment file path or name"),
    ({"a.toml": 'extends = "b.toml"', "b.toml": 'extends = "synthetic"\n[params]\n"HPC.nope" = 1'},
     "b.toml", "params.HPC.nope", "a parameter of HPCParams"),
    ({"a.toml": 'extends = "b.toml"\n[conditions.c]\nparams = { "LC.nope" = 1 }', "b.toml": 'extends = "synthetic"'},
     "a.toml", "conditions.c.params.LC.nope", "a parameter of"),
    ({"a.toml": 'extends = "b.toml"', "b.toml": 'extends = "synthetic"\n[world]\nframes = 3'},
     "b.toml", "world.frames", "a parameter of SyntheticParams"),
])
def test_errors_name_the_file_that_wrote_the_key(tmp_path, files, source, key, expected):
    for name, text in files.items():
        write(tmp_path, name, text)
    with pytest.raises(ConfigError) as info:
        load_experiment(tmp_path / "a.toml")
    assert (info.value.source, info.value.key) == (str((tmp_path / source).resolve()), key)
    assert expected in info.value.expected


def test_set_reaches_into_nested_world_tables():
    """``--set world.sources.TV.dims=5`` changes one key of a declared source and keeps the others."""
    exp = load_experiment("noisy_tv", sets=["world.sources.TV.dims=5", "world.visit_length=50"])
    world = exp.conditions["learning_progress"].world
    assert world["sources"]["TV"] == {"noise": "white", "dims": 5} and world["visit_length"] == 50
    swept = load_experiment("noisy_tv", sets=["world.sources.TV.dims=2,10"], runs=1)
    assert [c.world["sources"]["TV"]["dims"] for c in swept.select(["learning_progress"])] == [2, 10]
