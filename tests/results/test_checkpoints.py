"""Checkpoints and saved agents: a run stopped at 90 % continues from its last checkpoint, and a
saved agent continues to the tables of a run that was never stopped; the state format itself."""

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import neurocur
from neurocur.experiments import load_experiment, run_experiment
from neurocur.experiments.checkpointed import compute_and_write
from neurocur.experiments.run import run_one
from neurocur.results import ResultsError, ResultsStore, load
from neurocur.results import agents as agents_module
from neurocur.results.statefile import VERSION, StateError, load_state, save_state

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"
STEPS = 24_000  # long enough for the curious condition to store a module
#: a seed whose curious run 0 stores its module late (frame 22000), after the checkpoint the first
#: test continues from and after the 20000 frames the saved agent has seen: the continued part stores it
SEED = 4


NOISY_TV = ROOT / "neurocur" / "experiments_data" / "noisy_tv.toml"
#: the continuation cases: (file, condition, frames, seed). The synthetic world draws everything at its
#: reset; the noisy TV's world draws a new noise from its own generator (``world.np_random``, which only
#: the simulator seeds and the world holds) at every epoch of the TV, so a checkpoint that forgot the
#: world's generator would continue with other noise
CONTINUED = {"synthetic": (SYNTHETIC, "curious", STEPS, SEED), "noisy_tv": (NOISY_TV, "random_switching", 24_000, 1)}


def experiment(steps=STEPS):
    return load_experiment(SYNTHETIC, runs=1, steps=steps, seed=SEED)


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    out = tmp_path_factory.mktemp("reference") / "out"
    run_experiment(experiment(), out, jobs=1, conditions=["curious"], progress=False, checkpoint_every=0)
    return out


class Killed(Exception):
    pass


@pytest.mark.parametrize("case", list(CONTINUED))
def test_a_run_killed_at_90_percent_resumes_from_its_checkpoint_to_identical_tables(case, uninterrupted, tmp_path,
                                                                                   monkeypatch):
    path, name, steps, seed_entropy = CONTINUED[case]
    exp, out = load_experiment(path, runs=1, steps=steps, seed=seed_entropy), tmp_path / "out"
    reference = uninterrupted
    if case != "synthetic":
        reference = tmp_path / "reference"
        run_experiment(exp, reference, jobs=1, conditions=[name], progress=False, checkpoint_every=0)
    out.mkdir()
    shutil.copy(reference / "config.toml", out / "config.toml")
    condition, seed = exp.conditions[name], exp.run_seed(0)
    meta = {"condition": name, "run": 0, "steps": steps, "seed": {"entropy": seed.entropy, "spawn_key": [0]}}
    checkpoints = ResultsStore(out).checkpoints(name, 0, 10, meta)

    def kill(frames):
        if frames >= 0.9 * steps:
            raise Killed()

    with pytest.raises(Killed):
        run_one(condition, 0, steps, seed, progress=kill, checkpoints=checkpoints)
    saved = json.loads((checkpoints.folder / "state.json").read_text())["meta"]
    assert 0.5 * steps < saved["n_frames"] < 0.9 * steps and saved["n_episodes"] % 10 == 0

    resumed = []
    original = agents_module.Checkpoints.resume
    monkeypatch.setattr(agents_module.Checkpoints, "resume", lambda self, sim: resumed.append(original(self, sim))
                        or resumed[-1])
    compute_and_write(condition, 0, steps, seed, str(out), every=10)
    assert resumed == [True]  # continued from the checkpoint, not from the first frame
    assert not checkpoints.folder.exists()  # the written run's checkpoint is removed
    for a, b in zip(load(reference), load(out)):
        pd.testing.assert_frame_equal(a, b, check_exact=True)
    info = [json.loads((d / "runs" / name / "run-000" / "run.json").read_text()) for d in (reference, out)]
    assert info[0]["tables"] == info[1]["tables"]  # the Parquet files are the same bytes
    assert len(load(out)[1]) >= (1 if case == "synthetic" else 0)


def test_a_checkpoint_of_another_run_is_never_continued(tmp_path):
    exp = experiment(steps=3000)
    condition, seed = exp.conditions["curious"], exp.run_seed(0)
    meta = {"condition": "curious", "run": 0, "steps": 3000, "seed": {"entropy": seed.entropy, "spawn_key": [0]}}
    (tmp_path / "out").mkdir()
    checkpoints = ResultsStore(tmp_path / "out").checkpoints("curious", 0, 5, meta)
    run_one(condition, 0, 3000, seed, checkpoints=checkpoints)
    other = agents_module.Checkpoints(checkpoints.folder, 5, {**meta, "steps": 4000})
    sim = condition.circuit.build(condition.make_world(), seed=seed)
    assert other.resume(sim) is False and sim.n_frames == 0 and not checkpoints.folder.exists()


def test_a_written_run_leaves_its_condition_folder_to_a_run_that_has_not_saved_yet(tmp_path):
    """Two runs of one condition in flight: the first is written (its checkpoint removed) before the second
    saves its first checkpoint, which still finds its folder; the runner removes the empty folders at the end."""
    exp, out = experiment(steps=3000), tmp_path / "out"
    run_experiment(exp, out, jobs=1, conditions=["curious"], progress=False, checkpoint_every=5)
    assert not (out / "checkpoints").exists()  # the runner tidied up
    condition, store = exp.conditions["curious"], ResultsStore(out)
    seeds = [exp.run_seed(i) for i in (1, 2)]
    metas = [{"condition": "curious", "run": i, "steps": 3000, "seed": {"entropy": s.entropy, "spawn_key": [i]}}
             for i, s in zip((1, 2), seeds)]
    second = store.checkpoints("curious", 2, 5, metas[1])  # in flight, nothing saved yet
    compute_and_write(condition, 1, 3000, seeds[0], str(out), every=5)  # the first run is written
    assert second.folder.parent.is_dir()
    run_one(condition, 2, 3000, seeds[1], checkpoints=second)  # saves every 5 episodes into its folder
    assert (second.folder / "state.json").is_file()
    store.tidy_checkpoints()
    assert (out / "checkpoints" / "curious").is_dir()  # a kept checkpoint is not removed
    second.clear()
    store.tidy_checkpoints()
    assert not (out / "checkpoints").exists()


def test_checkpoints_are_on_by_default_only_for_long_runs():
    assert agents_module.checkpoint_every(350_000) == agents_module.CHECKPOINT_EPISODES
    assert agents_module.checkpoint_every(50_000) == 0
    assert agents_module.checkpoint_every(50_000, 7) == 7 and agents_module.checkpoint_every(10**6, 0) == 0


def test_load_agent_continues_a_run_to_the_tables_of_the_uninterrupted_run(uninterrupted, tmp_path):
    out = tmp_path / "out"
    run_experiment(experiment(steps=20_000), out, jobs=1, conditions=["curious"], progress=False, save_agent=True)
    assert (out / "runs" / "curious" / "run-000" / "agent" / "arrays.npz").is_file()
    sim = neurocur.load_agent(out, "curious", 0)
    episodes = load(out)[0]
    assert sim.n_frames == episodes["n_frames"].sum() and sim.n_episodes == len(episodes)
    pd.testing.assert_frame_equal(sim.episodes(), episodes.drop(columns=["condition", "run"]), check_exact=True)
    sim.run(STEPS - sim.n_frames)
    reference, modules = load(uninterrupted)
    pd.testing.assert_frame_equal(sim.episodes(), reference.drop(columns=["condition", "run"]), check_exact=True)
    stored = sim.products()["modules"]
    assert len(stored) == len(modules) >= 1
    assert stored["step"].tolist() == modules["step"].tolist()


def test_load_agent_refuses_a_run_without_an_agent_and_an_experiment_that_differs(uninterrupted, tmp_path):
    with pytest.raises(ResultsError, match="holds no saved agent"):
        neurocur.load_agent(uninterrupted, "curious", 0)
    out = tmp_path / "out"
    run_experiment(experiment(steps=3000), out, jobs=1, conditions=["curious"], progress=False, save_agent=True)
    other = load_experiment(SYNTHETIC, runs=1, steps=3000, seed=SEED, sets=["HPC.threshold=0.25"])
    with pytest.raises(ResultsError, match=r"key 'conditions.curious.resolved_circuit.regions.HPC.params.threshold'"):
        neurocur.load_agent(out, "curious", 0, experiment=other)


# --- the state format -----------------------------------------------------------------------------

class Holder:
    pass


def test_the_state_walker_round_trips_shared_state_generators_and_scalars(tmp_path):
    shared = np.arange(6.0).reshape(2, 3)
    a, b = Holder(), Holder()
    rng = np.random.default_rng(5)
    rng.random(3)
    a.__dict__.update(x=shared, rng=rng, scalar=np.float32(1.5), pairs={(1, "a"): [1, 2.5, None]}, other=b,
                      tags={"s", "t"}, objects=np.array(["a", 1], dtype=object), nan=float("nan"))
    b.__dict__.update(x=shared, back=a)
    save_state(tmp_path / "state", {"a": a, "b": b}, {"note": "n"})
    fresh_a, fresh_b = Holder(), Holder()
    assert load_state(tmp_path / "state", {"a": fresh_a, "b": fresh_b}) == {"note": "n"}
    assert fresh_a.x is fresh_b.x and np.array_equal(fresh_a.x, shared)
    assert fresh_a.other is fresh_b and fresh_b.back is fresh_a
    assert fresh_a.rng.random(4).tolist() == rng.random(4).tolist()
    assert type(fresh_a.scalar) is np.float32 and fresh_a.scalar == np.float32(1.5)
    assert fresh_a.pairs == {(1, "a"): [1, 2.5, None]} and fresh_a.tags == {"s", "t"}
    assert fresh_a.objects.tolist() == ["a", 1] and np.isnan(fresh_a.nan)


@pytest.mark.parametrize("value, named", [(lambda: 0, "function"), (pd.DataFrame(), "pandas"),
                                          (object(), "builtins.object")])
def test_the_state_walker_refuses_what_it_does_not_take_by_name(tmp_path, value, named):
    holder = Holder()
    holder.inner = {"k": [value]}
    with pytest.raises(StateError, match=rf"cannot save h.inner\['k'\]\[0\]: a .*{named}"):
        save_state(tmp_path / "state", {"h": holder})
    assert not (tmp_path / "state").exists()


def test_a_state_of_another_version_is_refused(tmp_path):
    holder = Holder()
    holder.x = 1
    save_state(tmp_path / "state", {"h": holder})
    body = json.loads((tmp_path / "state" / "state.json").read_text())
    (tmp_path / "state" / "state.json").write_text(json.dumps({**body, "version": 99}))
    with pytest.raises(StateError, match=rf"key 'version': expected {VERSION} .*got 99"):
        load_state(tmp_path / "state", {"h": Holder()})


def test_a_state_the_walker_cannot_save_fails_at_once_when_asked_for_and_is_skipped_by_default(tmp_path):
    exp = load_experiment("gym_classic", runs=1, steps=100)
    condition = next(iter(exp.conditions.values()))
    sim = condition.circuit.build(condition.make_world(), seed=exp.run_seed(0))
    asked = agents_module.Checkpoints(tmp_path / "c", 5, {"run": 0}, required=True)
    with pytest.raises(StateError, match=r"checkpoints and saved agents need state the walker takes; cannot save "
                                         r"world\.policy: a builtins\.function"):
        asked.resume(sim)
    default = agents_module.Checkpoints(tmp_path / "c", 5, {"run": 0})
    assert default.resume(sim) is False and default.every == 0
    default(sim)  # saves nothing, raises nothing
    assert not (tmp_path / "c").exists()


def test_paths_round_trip_through_the_state_walker(tmp_path):
    holder = Holder()
    holder.cache = Path("/some/cache.npz")
    save_state(tmp_path / "state", {"h": holder})
    fresh = Holder()
    load_state(tmp_path / "state", {"h": fresh})
    assert fresh.cache == Path("/some/cache.npz") and isinstance(fresh.cache, Path)
