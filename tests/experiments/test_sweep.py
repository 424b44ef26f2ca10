"""Grid sweeps: the [sweep] table, --set KEY=V1,V2, sweep columns, a folder that grows by points."""

import json
import os
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment, parse_set, run_experiment
from neurocur.experiments.resolve import Values
from neurocur.results import ResultsStore, load

ROOT = Path(__file__).resolve().parents[2]


def write(tmp_path, sweep='"PFC.discount" = [0.5, 0.9]\n"world.normalise" = ["global", "image"]'):
    path = tmp_path / "sweep.toml"
    path.write_text(textwrap.dedent(f"""\
        circuit = "{ROOT / 'neurocur' / 'circuits' / 'cd_misfa.toml'}"
        runs = 2
        steps = 600
        seed = 3
        [world]
        contexts = ["S-A", "S-B"]
        [sweep]
        {sweep}
        [conditions.curious]
        [conditions.random]
        circuit = "{ROOT / 'neurocur' / 'circuits' / 'lesion_lc_random.toml'}"
        """))
    return path


def test_the_grid_is_every_condition_at_every_point(tmp_path):
    exp = load_experiment(write(tmp_path))
    assert len(exp.conditions) == 2 * 2 * 2
    cond = exp.conditions["random@PFC.discount=0.9,world.normalise=image"]
    assert cond.sweep == {"PFC.discount": 0.9, "world.normalise": "image"}
    assert cond.circuit.specs["PFC"].params.discount == 0.9 and cond.world_params.normalise == "image"
    assert cond.circuit.lesions == (("LC", "random", {}),)
    assert cond.params["PFC.discount"] == 0.9 and "world.normalise" not in cond.params
    assert [c.name for c in exp.select(["curious"])] == [n for n in exp.conditions if n.startswith("curious@")]


def test_set_extends_restricts_and_adds_swept_keys(tmp_path):
    path = write(tmp_path)
    grown = load_experiment(path, sets=["PFC.discount=0.5,0.7,0.9"])
    assert {c.sweep["PFC.discount"] for c in grown.conditions.values()} == {0.5, 0.7, 0.9}
    restricted = load_experiment(path, sets=["world.normalise=image"])
    assert len(restricted.conditions) == 4 and {c.world_params.normalise for c in restricted.conditions.values()} == {"image"}
    added = load_experiment(path, sets=["LC.decay=0.99,0.9"])
    assert len(added.conditions) == 16 and all("LC.decay" in c.sweep for c in added.conditions.values())


def test_parse_set_values():
    assert parse_set("LC.gain=0.5") == ("LC.gain", 0.5)
    assert parse_set("world.frame_shape=[10, 10]") == ("world.frame_shape", [10, 10])
    key, values = parse_set("world.normalise=global,image")
    assert isinstance(values, Values) and (key, list(values)) == ("world.normalise", ["global", "image"])
    assert list(parse_set("LC.gain=0.5, 1, 2")[1]) == [0.5, 1, 2]


@pytest.mark.parametrize("sweep, key, expected", [
    ('"PFC.discount" = 0.5', "sweep.PFC.discount", "a non-empty list of values"),
    ('"PFC.discount" = []', "sweep.PFC.discount", "a non-empty list of values"),
    ('"PFC.discount" = [0.5, 0.5]', "sweep.PFC.discount", "distinct values"),
    ('runs = [1, 2]', "sweep.runs", '"REGION.param" or "world.KEY"'),
    ('"PFC.discount" = [0.5, 2.0]', "PFC.discount", "a number >= 0 and < 1"),
    ('"world.normalise" = ["global", "pixel"]', "sweep.world.normalise", "one of 'global', 'image'"),
])
def test_bad_sweeps_name_the_key(tmp_path, sweep, key, expected):
    with pytest.raises(ConfigError) as info:
        load_experiment(write(tmp_path, sweep))
    assert key in info.value.key and expected in info.value.expected


def test_bad_multi_value_set():
    with pytest.raises(ConfigError, match="several values only for a REGION.param or world.KEY"):
        load_experiment(ROOT / "neurocur" / "experiments_data" / "synthetic.toml", sets=["runs=1,2"])


def test_sweep_columns_and_a_folder_that_grows_by_points(tmp_path):
    path, out = write(tmp_path, '"PFC.discount" = [0.5, 0.9]'), tmp_path / "out"
    run_experiment(load_experiment(path), out, jobs=2, progress=False)
    episodes, modules = load(out)
    assert list(episodes.columns[:3]) == ["condition", "run", "PFC.discount"]
    assert list(modules.columns[:3]) == ["condition", "run", "PFC.discount"]
    assert episodes.groupby("PFC.discount")["condition"].nunique().to_dict() == {0.5: 2, 0.9: 2}
    store = ResultsStore(out)
    before = {p: os.stat(p / "run.json").st_mtime_ns for p in store.run_dirs()}
    run_experiment(load_experiment(path, sets=["PFC.discount=0.5,0.7,0.9"]), out, jobs=2, progress=False)
    after = {p: os.stat(p / "run.json").st_mtime_ns for p in store.run_dirs()}
    assert len(after) == 12 and all(after[p] == t for p, t in before.items())  # nothing re-run
    grown, _ = load(out)
    old = grown[grown["PFC.discount"] == 0.5].reset_index(drop=True)
    pd.testing.assert_frame_equal(old, episodes[episodes["PFC.discount"] == 0.5].reset_index(drop=True))
    # paired seeds: run i has the same seed at every point and in every condition, and another run another one
    seeds = {}
    for run_dir in ResultsStore(out).run_dirs():
        summary = json.loads((run_dir / "run.json").read_text())
        seeds.setdefault(summary["run"], set()).add(json.dumps(summary["seed"], sort_keys=True))
    assert sorted(seeds) == [0, 1] and all(len(s) == 1 for s in seeds.values())  # 6 runs each
    assert seeds[0] != seeds[1]
    first = grown[grown["episode"] == 0].groupby("run")["context"].nunique()  # hence the same first context
    assert (first == 1).all()


def test_the_shipped_sweep_grows_by_runs_and_by_a_point_without_re_running(tmp_path):
    """neurocur/experiments_data/sweep_pfc.toml: 3 x 3 points x 4 runs, then 6 runs and a fourth discount."""
    path, out = ROOT / "neurocur" / "experiments_data" / "sweep_pfc.toml", tmp_path / "grid"
    small = ["world.contexts=['S-A', 'S-B']"]
    run_experiment(load_experiment(path, steps=300, sets=small), out, jobs=2, progress=False)
    store = ResultsStore(out)
    first = {p: os.stat(p / "run.json").st_mtime_ns for p in store.run_dirs()}
    assert len(first) == 9 * 4
    grown = load_experiment(path, steps=300, runs=6, sets=[*small, "PFC.discount=0.5,0.9,0.99,0.999"])
    run_experiment(grown, out, jobs=2, progress=False)
    after = {p: os.stat(p / "run.json").st_mtime_ns for p in store.run_dirs()}
    assert len(after) == 12 * 6 and all(after[p] == t for p, t in first.items())  # nothing re-run
    assert store.config()["runs"] == 6
    episodes, _ = load(out)
    assert {"PFC.alpha", "PFC.discount"} <= set(episodes.columns)
    assert episodes.groupby(["PFC.alpha", "PFC.discount"])["run"].nunique().eq(6).all()
    assert sorted(episodes["PFC.discount"].unique()) == [0.5, 0.9, 0.99, 0.999]


def test_a_changed_point_is_refused_naming_the_key_and_both_values(tmp_path):
    path, out = write(tmp_path, '"PFC.discount" = [0.5]'), tmp_path / "out"
    run_experiment(load_experiment(path, runs=1, sets=["HPC.threshold=0.3"]), out, jobs=1, progress=False)
    with pytest.raises(ConfigError) as info:
        run_experiment(load_experiment(path, runs=1, sets=["HPC.threshold=0.25"]), out, jobs=1, progress=False)
    err = info.value  # the key has dots in its names (the point, the parameter): the values are still found
    assert err.key == "conditions.curious@PFC.discount=0.5.params.HPC.threshold"
    assert err.expected.startswith("0.25 (this experiment)") and err.got.startswith("0.3;")
    with pytest.raises(ConfigError) as info:
        run_experiment(load_experiment(path, runs=1), out, jobs=1, progress=False)
    assert info.value.expected.startswith("nothing (not set) (this experiment)") and info.value.got.startswith("0.3;")
