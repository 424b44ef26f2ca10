"""Benchmark of the simulated iCub world (neurocur.contexts.icub).

Prints the frames per second of simulation + rendering in one process, the time to
build the 2 × ``--episodes`` episode data set into an empty cache with ``--jobs``
worker processes, the time to read it back from the cache, and (with ``--omega``) the
learning cost Ω of each context (eq 40, η = 0.01, PCA to 98 % of the variance), and
(with ``--experiment``) the wall time of the whole iCub experiment
(``neurocur/experiments_data/icub.toml``: both conditions × 15 runs, into a temporary folder, the data
set already cached), of one run of each condition and the runs per core-hour, and (with
``--profile``) where one curious run's time goes: run 0 in this process under cProfile,
single-threaded BLAS, after a short warm-up run. ``--set`` passes settings to both, as
``neurocur run --set`` does (e.g. ``--set EC.dtype=float32``).

    python benchmarks/icub.py [--episodes 70] [--jobs 2] [--omega] [--experiment [--runs 15] [--run-jobs 1]]
                              [--profile] [--set KEY=VALUE ...] [--runs-only]
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import tempfile
import time
from pathlib import Path

import numpy as np

from neurocur.contexts.icub import ICubWorld, omega_episodes, pca_reduce
from neurocur.contexts.icub_data import EpisodeParams, _Simulation
from neurocur.contexts.icub_scene import OBJECTS, SceneParams

EXPERIMENT = Path(__file__).resolve().parents[1] / "neurocur" / "experiments_data" / "icub.toml"


def frames_per_second(n_episodes: int = 4) -> dict:
    """Simulation + rendering speed of each object's scene, in one process."""
    out = {}
    for obj in OBJECTS:
        sim = _Simulation(obj, SceneParams(), EpisodeParams())
        seeds = np.random.SeedSequence(0).spawn(n_episodes)
        start = time.perf_counter()
        n_frames = sum(len(sim.play(np.random.default_rng(s))[0]) for s in seeds)
        out[obj] = n_frames / (time.perf_counter() - start)
        sim.close()
    return out


def experiment_time(runs: int, jobs: int, sets=()) -> tuple[float, dict[str, list[float]], int]:
    """Wall time of ``neurocur/experiments_data/icub.toml`` (both conditions, ``runs`` runs each, ``jobs`` workers).

    The data set is built (or read from the default cache) before the clock starts.
    Returns (total seconds, each condition's runs' own seconds from their run.json, frames per run).
    """
    from neurocur.experiments import load_experiment, run_experiment

    exp = load_experiment(EXPERIMENT, runs=runs, sets=sets)
    for condition in exp.conditions.values():
        condition.world_class.prepare(condition.world_params)
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        run_experiment(exp, out, jobs=jobs, progress=False)
        total = time.perf_counter() - start
        per_run = {name: [json.loads(p.read_text())["seconds"] for p in sorted(Path(out).glob(f"runs/{name}/*/run.json"))]
                   for name in exp.conditions}
    return total, per_run, exp.steps


def profile_run(sets=(), top: int = 25) -> None:
    """Print cProfile's table (by own time) of run 0 of the curious condition, in this process."""
    from threadpoolctl import threadpool_limits

    from neurocur.experiments import load_experiment
    from neurocur.experiments.run import run_one

    exp = load_experiment(EXPERIMENT, sets=sets)
    condition = exp.conditions["curious"]
    condition.world_class.prepare(condition.world_params)
    run_one(condition, 0, 2000, exp.run_seed(0))  # warm-up: numba's cache, the data set's read
    profiler = cProfile.Profile()
    with threadpool_limits(1):
        start = time.perf_counter()
        profiler.runcall(run_one, condition, 0, exp.steps, exp.run_seed(0))
        seconds = time.perf_counter() - start
    print(f"profiled curious run 0 ({exp.steps} frames): {seconds:.1f} s under cProfile")
    pstats.Stats(profiler).sort_stats("tottime").print_stats(top)


def data_set(args) -> None:
    """Print the simulation speed, the data set's build and read times, its episodes and (``--omega``) Ω."""
    for obj, fps in frames_per_second().items():
        print(f"simulate+render, {obj:6s}: {fps:7.1f} frames/s (one process)")

    with tempfile.TemporaryDirectory() as cache:
        start = time.perf_counter()
        world = ICubWorld(n_episodes=args.episodes, seed=0, cache_dir=cache, n_jobs=args.jobs)
        build = time.perf_counter() - start
        start = time.perf_counter()
        ICubWorld(n_episodes=args.episodes, seed=0, cache_dir=cache)
        read = time.perf_counter() - start
        size = world.cache_path.stat().st_size / 2**20
    n_frames = sum(len(p.states) for p in world.pools.values())
    print(f"build 2 x {args.episodes} episodes ({n_frames} frames) on {args.jobs} process(es): {build:.1f} s")
    print(f"read from cache: {read:.2f} s ({size:.1f} MiB)")

    for c, name in enumerate(world.context_names):
        lengths = np.diff(world.pools[name].offsets)
        contact = np.mean(world.pools[name].contact >= 0)
        moves = np.array([world.object_positions(c, i)[-1, :2] - world.object_positions(c, i)[0, :2]
                          for i in range(world.n_episodes)])
        dist = np.linalg.norm(moves, axis=1)
        angle = np.degrees(np.arctan2(moves[:, 1], moves[:, 0]))
        print(
            f"{name:6s}: length {lengths.min()}-{lengths.max()} (mean {lengths.mean():.0f}), contact {contact:.0%}, "
            f"final displacement {dist.mean():.3f} +- {dist.std():.3f} m, direction {angle.mean():.1f} +- {angle.std():.1f} deg"
        )
        if args.omega:
            episodes = world.episodes(c)
            start = time.perf_counter()
            dims = pca_reduce(episodes, 0.98)[0].shape[1]
            value = omega_episodes(episodes, 0.01)
            print(f"        Omega = {value:.5f} (PCA 98 %: {dims} dims; {time.perf_counter() - start:.0f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=70)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--omega", action="store_true", help="also compute Omega of both contexts (~1 min)")
    parser.add_argument("--experiment", action="store_true",
                        help="also time neurocur/experiments_data/icub.toml, both conditions (~20 min at 15 runs, 1 job)")
    parser.add_argument("--runs", type=int, default=15, help="runs per condition for --experiment")
    parser.add_argument("--run-jobs", type=int, default=1, help="worker processes for --experiment")
    parser.add_argument("--profile", action="store_true", help="also profile one curious run (~1 min)")
    parser.add_argument("--runs-only", action="store_true",
                        help="skip the simulation and data-set figures (for --experiment and --profile)")
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                        help="settings for --experiment and --profile, e.g. EC.dtype=float32")
    args = parser.parse_args()

    if not args.runs_only:
        data_set(args)
    if args.experiment:
        total, per_run, steps = experiment_time(args.runs, args.run_jobs, args.set)
        n_runs = sum(len(s) for s in per_run.values())
        print(f"experiment icub.toml {' '.join(args.set)}, 2 conditions x {args.runs} runs x {steps} frames on "
              f"{args.run_jobs} process(es): {total:.0f} s ({total / 60:.1f} min), "
              f"{n_runs * 3600 / (total * args.run_jobs):.0f} runs per core-hour")
        for name, seconds in per_run.items():
            print(f"    {name}: one run {np.mean(seconds):.1f} +- {np.std(seconds):.1f} s "
                  f"({1e3 * np.mean(seconds) / steps:.2f} ms/frame), {3600 / np.mean(seconds):.0f} runs per core-hour")
    if args.profile:
        profile_run(args.set)


if __name__ == "__main__":
    main()
