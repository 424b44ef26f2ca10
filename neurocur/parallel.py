"""Running an experiment's runs in worker processes, into a resumable results folder.

Layout of a results folder::

    OUT/config.toml                               the fully resolved experiment (version, seeds)
    OUT/summary.json                              aggregate over every finished run
    OUT/runs/<condition>/run-<NNN>/episodes.parquet
    OUT/runs/<condition>/run-<NNN>/modules.parquet
    OUT/runs/<condition>/run-<NNN>/run.json       the run's summary (order, seed, ...)
    OUT/runs/<condition>/run-<NNN>/<name>.parquet  further tables of the world type
                                                  (iCub: features.parquet, see neurocur.experiment)

Every run is written into ``OUT/.partial/`` and moved into place with one
``os.replace`` when it is complete, so a run folder exists only when all its files
do. Running again into the same folder skips the finished runs; an interrupted sweep
resumes where it stopped. Conditions new to a folder are added to it (a study can grow
row by row), and descriptions may be reworded. A folder whose ``config.toml`` differs from the experiment
(another seed, step count, circuit, parameter...) is refused, naming the first
differing key.

Before the workers start, each selected condition's world is prepared once
(:func:`~neurocur.experiment.prepare_world`: an iCub episode data set is simulated
into its cache), so that workers only read it.

Runs are always computed in worker processes (``forkserver``, else ``spawn``), each
with single-threaded BLAS, so a seed gives the same tables for any number of jobs.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import shutil
import sys
import tomllib
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from neurocur.config import ConfigError
from neurocur.experiment import (
    Condition,
    Experiment,
    RunResult,
    dumps_toml,
    first_difference,
    prepare_world,
    run_one,
    source_spec,
)

__all__ = ["run_experiment", "run_dir", "completed_runs", "write_run", "write_summary"]

CONFIG = "config.toml"
SUMMARY = "summary.json"
PARTIAL = ".partial"
_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
_HEADER = """Resolved experiment written by neurocur; do not edit (resuming into this folder compares it).
Seeds: run i of every condition uses numpy SeedSequence(seeds.entropy, spawn_key=seeds.spawn_keys[i]);
the circuit splits it into one child per region (the sensory region's child seeds the world)."""


def run_dir(out: Path, condition: str, run: int) -> Path:
    """Folder of run ``run`` of ``condition``."""
    return Path(out) / "runs" / condition / f"run-{run:03d}"


def completed_runs(out: Path, conditions, runs: int) -> set[tuple[str, int]]:
    """The (condition, run) pairs already present in ``out``."""
    return {(c, i) for c in conditions for i in range(runs) if (run_dir(out, c, i) / "run.json").is_file()}


def _prepare_folder(exp: Experiment, out: Path) -> Experiment:
    """Create ``out`` with config.toml, or check that it holds this experiment (resume)."""
    config_path = out / CONFIG
    existing = None
    if config_path.is_file():
        with config_path.open("rb") as fh:
            existing = tomllib.load(fh)
    if exp.seed is None:
        seed = existing["seeds"]["entropy"] if existing else int(np.random.SeedSequence().entropy % 2**63)
        exp = Experiment(exp.name, exp.path, exp.description, exp.runs, exp.steps, seed, exp.conditions)
    config = tomllib.loads(dumps_toml(exp.resolved()))
    if existing is not None:
        # a study may grow: conditions new to the folder are added, the others must be unchanged
        old_conditions, new_conditions = existing.get("conditions", {}), config.get("conditions", {})
        shared = [c for c in new_conditions if c in old_conditions]
        key = first_difference(_without_descriptions({**existing, "conditions": {c: old_conditions[c] for c in shared}}),
                               _without_descriptions({**config, "conditions": {c: new_conditions[c] for c in shared}}))
        if key is not None:
            raise ConfigError(config_path, key, f"{_lookup(config, key)!r} (this experiment) to resume into this folder",
                              f"{_lookup(existing, key)!r}; use another --out folder or remove this one")
        grown = {**existing, "conditions": {**old_conditions, **new_conditions}}
        if "description" in config:
            grown["description"] = config["description"]
        if grown != existing:
            _atomic_text(config_path, dumps_toml(grown, header=_HEADER))
        return exp
    out.mkdir(parents=True, exist_ok=True)
    _atomic_text(config_path, dumps_toml(config, header=_HEADER))
    return exp


def _without_descriptions(tree):
    """``tree`` without its ``description`` entries: prose, which does not change a result."""
    if isinstance(tree, dict):
        return {k: _without_descriptions(v) for k, v in tree.items() if k != "description"}
    return tree


def _lookup(tree, dotted: str):
    node = tree
    for part in dotted.replace("[", ".[").split("."):
        if not part:
            continue
        try:
            node = node[int(part[1:-1])] if part.startswith("[") else node[part]
        except (KeyError, IndexError, TypeError):
            return "(missing)"
    return node if not isinstance(node, (dict, list)) else "(a table)" if isinstance(node, dict) else node


def _atomic_text(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def write_run(out: Path, result: RunResult) -> Path:
    """Write one run's tables and summary atomically into its run folder."""
    final = run_dir(out, result.condition, result.run)
    tmp = Path(out) / PARTIAL / f"{result.condition}-run-{result.run:03d}-{os.getpid()}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    result.episodes.to_parquet(tmp / "episodes.parquet", index=False)
    result.modules.to_parquet(tmp / "modules.parquet", index=False)
    for name, table in result.tables.items():
        table.to_parquet(tmp / f"{name}.parquet", index=False)
    (tmp / "run.json").write_text(json.dumps(result.summary, indent=2) + "\n", encoding="utf-8")
    final.parent.mkdir(parents=True, exist_ok=True)
    os.replace(tmp, final)
    return final


def _worker(condition: Condition, run: int, steps: int, seed: np.random.SeedSequence, out: str) -> tuple[str, int]:
    write_run(Path(out), run_one(condition, run, steps, seed))
    return condition.name, run


@contextmanager
def _single_threaded_children():
    """Worker processes inherit single-threaded BLAS/numba settings (restored afterwards)."""
    saved = {k: os.environ.get(k) for k in _THREAD_VARS}
    os.environ.update({k: "1" for k in _THREAD_VARS})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _mp_context():
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _progress_bar(total: int, initial: int, enabled: bool | None):
    from tqdm import tqdm

    disable = not sys.stderr.isatty() if enabled is None else not enabled
    return tqdm(total=total, initial=initial, unit="run", desc="runs", file=sys.stderr, disable=disable,
                dynamic_ncols=True)


def run_experiment(exp: Experiment, out, *, jobs: int | None = None, conditions=None,
                   progress: bool | None = None) -> Path:
    """Run every (selected condition × run) of ``exp`` into the results folder ``out``.

    ``jobs``: worker processes (default: all cores). ``conditions``: names to run
    (default: all). ``progress``: a tqdm bar of finished runs on stderr; ``None`` shows
    it only when stderr is a terminal. Returns ``out`` (summary.json updated).
    """
    out = Path(out)
    selected = exp.select(conditions)
    exp = _prepare_folder(exp, out)
    shutil.rmtree(out / PARTIAL, ignore_errors=True)
    names = [c.name for c in selected]
    done = completed_runs(out, names, exp.runs)
    todo = [(c, i) for c in selected for i in range(exp.runs) if (c.name, i) not in done]
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(todo) or 1))
    bar = _progress_bar(len(names) * exp.runs, len(done), progress)
    try:
        if todo:
            for world in {json.dumps(c.world, sort_keys=True): c.world for c, _ in todo}.values():
                prepare_world(world)
            with _single_threaded_children(), ProcessPoolExecutor(max_workers=jobs, mp_context=_mp_context()) as pool:
                pending = {pool.submit(_worker, c, i, exp.steps, exp.run_seed(i), str(out)) for c, i in todo}
                try:
                    while pending:
                        finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                        for future in finished:
                            future.result()
                            bar.update(1)
                except BaseException:
                    for future in pending:
                        future.cancel()
                    raise
    finally:
        bar.close()
        shutil.rmtree(out / PARTIAL, ignore_errors=True)
    write_summary(out, exp)
    return out


def write_summary(out: Path, exp: Experiment) -> dict:
    """Aggregate every finished run of ``out`` into ``summary.json`` (via neurocur.analysis)."""
    from neurocur.analysis.io import load
    from neurocur.analysis.stats import summary

    episodes, modules = load(out)
    present = [c for c in exp.conditions.values() if c.name in set(episodes["condition"])]
    specs = {c.name: source_spec(c) for c in present}
    reference = next(iter(exp.conditions))
    if len(set(specs.values())) <= 1:
        spec = next(iter(specs.values()))
        result = {"spec": _spec_dict(spec), **summary(episodes, modules, spec, reference=reference)}
    else:
        result = {"conditions": {}}
        for name, spec in specs.items():
            keep_e, keep_m = episodes["condition"] == name, modules["condition"] == name
            result["conditions"][name] = {"spec": _spec_dict(spec),
                                          **summary(episodes[keep_e], modules[keep_m], spec, reference=reference)}
    _atomic_text(out / SUMMARY, json.dumps(result, indent=2, ensure_ascii=False) + "\n")
    return result


def _spec_dict(spec) -> dict:
    return {"context_names": list(spec.context_names), "context_sources": list(spec.context_sources),
            "learnable": list(spec.learnable)}
