"""A checkpoint or a saved agent is trusted only when it proves itself: its digests, its run (condition,
number, seed, steps, parameters, code), its counters and arrays, and no link on the way. A checkpoint
that fails is discarded with one line and its run starts again (to the tables of the uninterrupted
run); a saved agent that fails is refused with one line naming the file and what did not match."""

import hashlib
import io
import json
import os
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
from neurocur.results.runinfo import seed_json

ROOT = Path(__file__).resolve().parents[2]
SYNTHETIC = ROOT / "neurocur" / "experiments_data" / "synthetic.toml"
STEPS, EVERY, SEED = 6000, 5, 4


def experiment(sets=()):
    return load_experiment(SYNTHETIC, runs=1, steps=STEPS, seed=SEED, sets=list(sets))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The curious condition's run 0, never stopped (its tables) and with its agent (for load_agent)."""
    out = tmp_path_factory.mktemp("reference") / "out"
    run_experiment(experiment(), out, jobs=1, conditions=["curious"], progress=False, checkpoint_every=0,
                   save_agent=True)
    return out


class Killed(Exception):
    pass


def stopped_run(out, exp, config_from=None):
    """A run of ``exp`` into ``out`` killed at 60 % of its frames: its last checkpoint is in ``out``."""
    out.mkdir()
    store = ResultsStore(out)
    if config_from is not None:
        shutil.copy(config_from / "config.toml", out / "config.toml")
    else:
        store.save_config(store.check(exp.resolved()))
    condition, seed = exp.conditions["curious"], exp.run_seed(0)
    meta = {"condition": "curious", "run": 0, "steps": STEPS, "seed": seed_json(seed)}
    checkpoints = store.checkpoints("curious", 0, EVERY, meta)

    def kill(frames):
        if frames >= 0.6 * STEPS:
            raise Killed()

    with pytest.raises(Killed):
        run_one(condition, 0, STEPS, seed, progress=kill, checkpoints=checkpoints)
    assert (checkpoints.folder / "state.json").is_file()
    return checkpoints.folder


def resume(out, monkeypatch):
    """Compute run 0 again into ``out`` as a worker does; returns whether it continued from a checkpoint."""
    exp = experiment()
    resumed = []
    original = agents_module.Checkpoints.resume
    monkeypatch.setattr(agents_module.Checkpoints, "resume",
                        lambda self, sim: resumed.append(original(self, sim)) or resumed[-1])
    compute_and_write(exp.conditions["curious"], 0, STEPS, exp.run_seed(0), str(out), every=EVERY)
    return resumed == [True]


def assert_same_tables(a, b):
    for x, y in zip(load(a), load(b)):
        pd.testing.assert_frame_equal(x, y, check_exact=True)


def discarded_line(capsys, *words):
    """The one line a discarded checkpoint printed on stderr, naming each of ``words``."""
    lines = [line for line in capsys.readouterr().err.splitlines() if "discarded the checkpoint" in line]
    assert len(lines) == 1, lines
    assert "Traceback" not in lines[0] and all(word in lines[0] for word in words), lines[0]
    return lines[0]


def reseal(folder):
    """Recompute the digests of a state folder's ``state.json`` after it was edited (a careful forger)."""
    path = folder / "state.json"
    body = json.loads(path.read_text())
    digests = body.pop("sha256")
    digests["arrays.npz"] = hashlib.sha256((folder / "arrays.npz").read_bytes()).hexdigest()
    canonical = json.dumps(body, sort_keys=True, separators=(",", ":")).encode()
    body["sha256"] = {**digests, "state": hashlib.sha256(canonical).hexdigest()}
    path.write_text(json.dumps(body))


def edit_state(folder, change, *, sealed=True):
    path = folder / "state.json"
    body = json.loads(path.read_text())
    change(body)
    path.write_text(json.dumps(body))
    if sealed:
        reseal(folder)


def set_frames(value):
    def change(body):
        body["roots"]["simulator"]["n_frames"] = value
        body["meta"]["n_frames"] = value
    return change


# --- checkpoints -----------------------------------------------------------------------------------

@pytest.mark.parametrize("sealed", [False, True], ids=["edited", "edited-and-resealed"])
def test_a_checkpoint_whose_frame_counter_is_nan_is_discarded_and_the_run_restarts(reference, tmp_path, monkeypatch,
                                                                                   capsys, sealed):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    edit_state(folder, set_frames(float("nan")), sealed=sealed)
    assert not resume(out, monkeypatch)
    discarded_line(capsys, str(folder / "state.json"), "sha256" if not sealed else "n_frames")
    assert_same_tables(reference, out)
    assert load(out)[0]["n_frames"].sum() >= STEPS


@pytest.mark.parametrize("value", [-5, 1e300, 12.5])
def test_a_resealed_checkpoint_with_a_negative_or_fractional_counter_is_discarded(reference, tmp_path, monkeypatch,
                                                                                  capsys, value):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    edit_state(folder, set_frames(value))
    assert not resume(out, monkeypatch)
    discarded_line(capsys, "n_frames")
    assert_same_tables(reference, out)


def test_a_resealed_checkpoint_whose_frame_counter_disagrees_with_its_recorder_is_discarded(reference, tmp_path,
                                                                                            monkeypatch, capsys):
    """A plausible counter (an integer, 1000 frames on) that the recorded episodes do not add up to."""
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    saved = json.loads((folder / "state.json").read_text())["meta"]["n_frames"]
    edit_state(folder, set_frames(saved + 1000))
    assert not resume(out, monkeypatch)
    discarded_line(capsys, f"key 'roots.simulator.n_frames': expected {saved}, the frames its recorder")
    assert_same_tables(reference, out)


def test_a_checkpoint_copied_from_a_run_with_other_parameters_is_discarded(reference, tmp_path, monkeypatch, capsys):
    other = tmp_path / "other"
    stopped_run(other, experiment(["HPC.threshold=0.5"]))
    out = tmp_path / "out"
    out.mkdir()
    shutil.copy(reference / "config.toml", out / "config.toml")
    shutil.copytree(other / "checkpoints", out / "checkpoints")
    assert not resume(out, monkeypatch)
    discarded_line(capsys, "key 'meta.params'")
    assert_same_tables(reference, out)


def test_a_checkpoint_saved_by_other_code_is_discarded(reference, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    edit_state(folder, lambda body: body["meta"]["code"].update(source="0123456789abcdef"))
    assert not resume(out, monkeypatch)
    discarded_line(capsys, "key 'meta.code'")
    assert_same_tables(reference, out)


def test_a_truncated_checkpoint_is_discarded_with_one_line_and_not_kept(reference, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    arrays = folder / "arrays.npz"
    arrays.write_bytes(arrays.read_bytes()[: arrays.stat().st_size // 2])
    assert not resume(out, monkeypatch)
    discarded_line(capsys, str(arrays))
    assert not folder.exists()
    assert_same_tables(reference, out)


@pytest.mark.parametrize("bad", ["object", "shape"])
def test_a_checkpoint_with_an_object_array_or_an_undeclared_shape_is_discarded_naming_the_file(
        reference, tmp_path, monkeypatch, capsys, bad):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    with np.load(folder / "arrays.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    key = max(arrays, key=lambda k: arrays[k].size)
    arrays[key] = np.array([None, 1], dtype=object) if bad == "object" else arrays[key].reshape(-1)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    (folder / "arrays.npz").write_bytes(buffer.getvalue())
    reseal(folder)  # the digests agree: the arrays themselves are checked
    assert not resume(out, monkeypatch)
    line = discarded_line(capsys, str(folder / "arrays.npz"))
    assert ("without objects" if bad == "object" else f"array {key!r}") in line
    assert_same_tables(reference, out)


def test_a_checkpoint_folder_replaced_by_a_link_is_not_read_through_it(reference, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    outside = tmp_path / "outside"
    os.replace(folder, outside)  # a checkpoint of this very run: read through the link, it would be continued
    folder.symlink_to(outside, target_is_directory=True)
    assert not resume(out, monkeypatch)
    discarded_line(capsys, str(folder), "symbolic link")
    assert not os.path.lexists(folder) and (outside / "arrays.npz").is_file()  # the link went, not its target
    assert_same_tables(reference, out)


@pytest.mark.parametrize("name", ["state.json", "arrays.npz"])
def test_a_checkpoint_file_replaced_by_a_link_is_not_read_through_it(reference, tmp_path, monkeypatch, capsys, name):
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    outside = tmp_path / name
    os.replace(folder / name, outside)
    (folder / name).symlink_to(outside)
    assert not resume(out, monkeypatch)
    discarded_line(capsys, str(folder / name), "symbolic link")
    assert outside.is_file()
    assert_same_tables(reference, out)


def test_a_run_killed_while_it_saves_a_checkpoint_leaves_no_temporary_folder(reference, tmp_path):
    """A save killed between its temporary folder and the rename leaves ``.run-000.<pid>.tmp`` (and
    ``.old``) beside the checkpoint; the resumed run removes them and the finished folder holds none."""
    out = tmp_path / "out"
    folder = stopped_run(out, experiment(), reference)
    for suffix in ("tmp", "old"):
        shutil.copytree(folder, folder.with_name(f".{folder.name}.999999.{suffix}"))
    run_experiment(experiment(), out, jobs=1, conditions=["curious"], progress=False, checkpoint_every=EVERY)
    assert not (out / "checkpoints").exists()
    assert_same_tables(reference, out)


def test_a_checkpoint_that_proves_itself_is_continued(reference, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    stopped_run(out, experiment(), reference)
    assert resume(out, monkeypatch)
    assert "discarded" not in capsys.readouterr().err
    assert_same_tables(reference, out)


# --- saved agents ----------------------------------------------------------------------------------

@pytest.fixture
def agent_folder(reference, tmp_path):
    """A copy of the reference folder, whose run 0 keeps its agent, to break."""
    return Path(shutil.copytree(reference, tmp_path / "out", symlinks=True))


def agent_dir(out):
    return out / "runs" / "curious" / "run-000" / "agent"


def reseal_run(out):
    """Record the agent's files as they are now in ``run.json`` (a forger who rewrites it too)."""
    run_json = agent_dir(out).parent / "run.json"
    info = json.loads(run_json.read_text())
    info["agent"] = {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(agent_dir(out).iterdir())}
    run_json.write_text(json.dumps(info))


def test_run_json_records_the_digest_of_the_saved_agent_and_loading_checks_it(agent_folder):
    info = json.loads((agent_dir(agent_folder).parent / "run.json").read_text())
    assert info["agent"] == {name: hashlib.sha256((agent_dir(agent_folder) / name).read_bytes()).hexdigest()
                             for name in ("arrays.npz", "state.json")}
    assert neurocur.load_agent(agent_folder, "curious", 0).n_frames >= STEPS
    edit_state(agent_dir(agent_folder), set_frames(7))
    with pytest.raises(ResultsError, match=r"run.json: key 'agent': expected the sha256 of the saved agent's files"):
        load(agent_folder)


def test_an_agent_that_run_json_does_not_record_is_never_loaded_but_the_tables_are(agent_folder, reference):
    run_json = agent_dir(agent_folder).parent / "run.json"
    info = json.loads(run_json.read_text())
    del info["agent"]
    run_json.write_text(json.dumps(info))
    assert_same_tables(reference, agent_folder)
    with pytest.raises(ResultsError, match=r"run.json: key 'agent': expected the sha256 of the saved agent's files, "
                                           r"got nothing"):
        neurocur.load_agent(agent_folder, "curious", 0)


def test_a_saved_agent_must_record_its_parameters_and_code(agent_folder):
    body = json.loads((agent_dir(agent_folder) / "state.json").read_text())
    config = ResultsStore(agent_folder).config()
    assert body["meta"]["params"] == agents_module.params_digest(config, "curious")
    assert body["meta"]["code"] in config["code"]


def wrong_shape(folder):
    with np.load(folder / "arrays.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    key = max(arrays, key=lambda k: arrays[k].size)
    arrays[key] = arrays[key][::-1].T.copy()
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    (folder / "arrays.npz").write_bytes(buffer.getvalue())


def nan_in_an_array(folder):
    with np.load(folder / "arrays.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    key = next(k for k, a in arrays.items() if a.dtype.kind == "f" and a.size and np.isfinite(a).all())
    arrays[key].flat[0] = np.nan
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    (folder / "arrays.npz").write_bytes(buffer.getvalue())


@pytest.mark.parametrize("change, named", [
    (wrong_shape, r"arrays.npz: expected the sha256 that state.json records"),
    (nan_in_an_array, r"arrays.npz: expected the sha256 that state.json records"),
    (lambda f: (wrong_shape(f), reseal(f)), r"arrays.npz: array 'a\d+': expected dtype .* as state.json declares"),
    (lambda f: edit_state(f, set_frames(float("nan"))), r"state.json: key 'roots.simulator.n_frames': expected an "
                                                        r"integer"),
    (lambda f: edit_state(f, set_frames(float("inf"))), r"state.json: key 'roots.simulator.n_frames': expected an "
                                                        r"integer"),
    (lambda f: edit_state(f, set_frames(-5)), r"state.json: key 'roots.simulator.n_frames': expected a non-negative"),
    (lambda f: edit_state(f, set_frames(float("nan")), sealed=False), r"state.json: key 'sha256.state'"),
    (lambda f: edit_state(f, lambda b: b["meta"].update(params="0" * 64)), r"state.json: key 'meta.params'"),
    (lambda f: edit_state(f, lambda b: b["meta"]["code"].update(version="0.0.0")), r"state.json: key 'meta.code'"),
], ids=["shape", "nan-array", "shape-resealed", "nan-counter", "inf-counter", "negative-counter", "unsealed",
        "params", "code"])
def test_load_agent_refuses_a_saved_agent_that_does_not_prove_itself(agent_folder, change, named):
    change(agent_dir(agent_folder))
    reseal_run(agent_folder)  # run.json agrees: the agent's own checks must catch it
    with pytest.raises(ResultsError, match=named) as info:
        neurocur.load_agent(agent_folder, "curious", 0)
    assert str(agent_dir(agent_folder)) in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("what", ["state.json", "arrays.npz", "agent"])
def test_load_agent_follows_no_link_in_a_saved_agent(agent_folder, tmp_path, what):
    target = agent_dir(agent_folder) if what == "agent" else agent_dir(agent_folder) / what
    outside = tmp_path / f"outside-{what}"
    os.replace(target, outside)  # the very files of this agent: read through a link, they would be accepted
    target.symlink_to(outside, target_is_directory=outside.is_dir())
    with pytest.raises(ResultsError, match=r"is a symbolic link|got a symbolic link") as info:
        neurocur.load_agent(agent_folder, "curious", 0)
    assert str(target) in str(info.value) and "\n" not in str(info.value)
