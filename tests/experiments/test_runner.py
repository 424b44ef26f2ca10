"""The runner: worker processes, atomic run folders, resume, determinism across --jobs."""

import json
import os
import re
import tomllib
from pathlib import Path

import pandas as pd
import pytest

from neurocur.analysis import write_summary
from neurocur.config import ConfigError
from neurocur.experiments import load_experiment, run_experiment
from neurocur.results import ResultsStore
from neurocur.results.store import PARTIAL


def run_dir(out, condition, run):
    return ResultsStore(out).run_dir(condition, run)


def completed_runs(out, conditions, runs):
    return ResultsStore(out).completed(conditions, runs)

SYNTHETIC = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml"
RUNS, STEPS = 2, 3000


def tiny(**kw):
    return load_experiment(SYNTHETIC, runs=kw.pop("runs", RUNS), steps=kw.pop("steps", STEPS), **kw)


def tables(out):
    return {
        (p.parent.parent.name, p.parent.name, p.name): pd.read_parquet(p)
        for p in sorted(Path(out).glob("runs/*/*/*.parquet"))
    }


PAIR = ["curious", "random_switching"]


@pytest.fixture(scope="module")
def two_jobs(tmp_path_factory):
    out = tmp_path_factory.mktemp("jobs2")
    run_experiment(tiny(), out, jobs=2, progress=False, conditions=PAIR)
    write_summary(out)
    return out


def test_folder_layout(two_jobs):
    assert (two_jobs / "config.toml").is_file() and (two_jobs / "summary.json").is_file()
    assert not (two_jobs / PARTIAL).exists()
    for cond in ("curious", "random_switching"):
        for i in range(RUNS):
            d = run_dir(two_jobs, cond, i)
            assert d == two_jobs / "runs" / cond / f"run-{i:03d}"
            assert {p.name for p in d.iterdir()} == {"episodes.parquet", "modules.parquet", "run.json"}
            summary = json.loads((d / "run.json").read_text())
            assert summary["condition"] == cond and summary["run"] == i and summary["frames"] >= STEPS
    assert completed_runs(two_jobs, ["curious", "random_switching"], RUNS) == {
        (c, i) for c in ("curious", "random_switching") for i in range(RUNS)}
    summary = json.loads((two_jobs / "summary.json").read_text())
    assert summary["n_runs"] == {"curious": RUNS, "random_switching": RUNS}
    assert summary["spec"]["learnable"] == ["S-A", "S-B", "S-C"]
    seconds = [json.loads(p.read_text())["seconds"] for p in two_jobs.glob("runs/*/*/run.json")]
    rate = summary["throughput"]
    assert rate["runs"] == 2 * RUNS and rate["seconds_per_run"] == pytest.approx(sum(seconds) / len(seconds))
    assert rate["runs_per_core_hour"] == pytest.approx(3600 * len(seconds) / sum(seconds))


def test_same_tables_with_one_or_two_jobs(two_jobs, tmp_path):
    run_experiment(tiny(), tmp_path, jobs=1, progress=False, conditions=PAIR)
    a, b = tables(two_jobs), tables(tmp_path)
    assert a.keys() == b.keys() and len(a) == 2 * RUNS * 2
    for key in a:
        pd.testing.assert_frame_equal(a[key], b[key])
    # paired runs: run i of both conditions starts in the same context of the same world
    ep = pd.concat(t for k, t in a.items() if k[2] == "episodes.parquet")
    first = ep[ep["episode"] == 0].pivot(index="run", columns="condition", values="context")
    assert (first["curious"] == first["random_switching"]).all()


def test_resume_recomputes_only_the_missing_run(two_jobs, tmp_path):
    out = tmp_path / "copy"
    import shutil

    shutil.copytree(two_jobs, out)
    victim = run_dir(out, "curious", 1)
    shutil.rmtree(victim)
    (out / PARTIAL / "curious-run-001-999").mkdir(parents=True)  # debris of an interrupted run
    before = {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*/*")}
    run_experiment(tiny(), out, jobs=2, progress=False, conditions=PAIR)
    after = {p: p.stat().st_mtime_ns for p in out.glob("runs/*/*/*")}
    assert {p for p in after if p not in before} == {victim / n for n in ("episodes.parquet", "modules.parquet", "run.json")}
    assert all(after[p] == t for p, t in before.items())
    assert not (out / PARTIAL).exists()
    pd.testing.assert_frame_equal(pd.read_parquet(victim / "episodes.parquet"),
                                  pd.read_parquet(run_dir(two_jobs, "curious", 1) / "episodes.parquet"))


def test_nothing_to_do_when_complete(two_jobs):
    before = {p: p.stat().st_mtime_ns for p in two_jobs.glob("runs/*/*/*")}
    run_experiment(tiny(), two_jobs, jobs=2, progress=False, conditions=["curious"])
    assert {p: p.stat().st_mtime_ns for p in two_jobs.glob("runs/*/*/*")} == before


@pytest.mark.parametrize("change, key", [
    ({"steps": STEPS + 1}, "steps"),
    ({"sets": ["seed=1"]}, "seeds.entropy"),
    ({"sets": ["HPC.threshold=0.2"]}, "conditions.curious.params.HPC.threshold"),
])
def test_refuses_to_resume_a_different_experiment(two_jobs, change, key):
    with pytest.raises(ConfigError) as info:
        run_experiment(tiny(**change), two_jobs, jobs=1, progress=False)
    assert info.value.key == key and "to resume into this folder" in str(info.value)


def test_experiment_without_seed_adopts_the_folders_seed(tmp_path):
    text = re.sub(r"(?m)^seed = .*$", "", SYNTHETIC.read_text())
    exp_path = tmp_path / "noseed.toml"
    exp_path.write_text(text)  # the circuits are named, so the copy needs no path rewriting
    exp = load_experiment(exp_path, runs=1, steps=200)
    assert exp.seed is None
    out = tmp_path / "out"
    run_experiment(exp, out, jobs=1, conditions=["curious"], progress=False)
    seed = json.loads((run_dir(out, "curious", 0) / "run.json").read_text())["seed"]["entropy"]
    assert isinstance(seed, int) and 0 <= seed < 2**63
    mtime = os.stat(run_dir(out, "curious", 0) / "run.json").st_mtime_ns
    run_experiment(exp, out, jobs=1, conditions=["curious"], progress=False)  # no "differs" error
    assert os.stat(run_dir(out, "curious", 0) / "run.json").st_mtime_ns == mtime


def test_a_study_grows_by_new_conditions_but_old_ones_must_not_change(tmp_path):
    base = SYNTHETIC.read_text()
    study = tmp_path / "study.toml"  # the same file, edited between the two calls
    study.write_text(base)
    out = tmp_path / "out"
    run_experiment(load_experiment(study, runs=1, steps=200), out, jobs=1, conditions=["curious"], progress=False)
    mtime = os.stat(run_dir(out, "curious", 0) / "run.json").st_mtime_ns
    study.write_text(base + '\n[conditions.low_threshold]\nparams = { "HPC.threshold" = 0.2 }\n')
    run_experiment(load_experiment(study, runs=1, steps=200), out, jobs=1, progress=False)
    assert os.stat(run_dir(out, "curious", 0) / "run.json").st_mtime_ns == mtime  # kept, not recomputed
    assert completed_runs(out, ["curious", "random_switching", "literal", "low_threshold"], 1) == {
        ("curious", 0), ("random_switching", 0), ("literal", 0), ("low_threshold", 0)}
    with (out / "config.toml").open("rb") as fh:
        assert set(tomllib.load(fh)["conditions"]) == {"curious", "random_switching", "literal", "low_threshold"}
    study.write_text(study.read_text().replace('description = "Section 4.3 control', 'description = "The control'))
    run_experiment(load_experiment(study, runs=1, steps=200), out, jobs=1, progress=False)  # prose may change
    with (out / "config.toml").open("rb") as fh:
        assert tomllib.load(fh)["conditions"]["random_switching"]["description"].startswith("The control")
    study.write_text(study.read_text().replace('"HPC.threshold" = 0.2', '"HPC.threshold" = 0.25'))
    with pytest.raises(ConfigError) as info:
        run_experiment(load_experiment(study, runs=1, steps=200), out, jobs=1, progress=False)
    assert info.value.key == "conditions.low_threshold.params.HPC.threshold"


def test_the_fork_servers_warm_up_module_loads_the_compiled_kernels_once_for_every_worker():
    """Importing neurocur.experiments.warm (the fork server does, after the runner) loads the
    kernels a synthetic run calls, which a fresh process has not loaded."""
    import subprocess
    import sys

    code = ("from neurocur.learn._kernels import incsfa_fit\n"
            "from neurocur.learn._roc_kernels import roc_episode_error\n"
            "before = len(incsfa_fit.signatures), len(roc_episode_error.signatures)\n"
            "import neurocur.experiments.warm\n"
            "print(before, (len(incsfa_fit.signatures), len(roc_episode_error.signatures)))\n")
    printed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert printed.strip() == "(0, 0) (1, 1)"
