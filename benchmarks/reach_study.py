"""Can any reading of the paper's open choices give its synthetic statistics together? (a study of
results folders, not a test; docs/reproduction.md, section 2.11).

    python benchmarks/reach_study.py design --out study/                 # study/reach.toml, study/design.csv
    neurocur run study/reach.toml --jobs 1 --out study/runs                # resumable; --runs 8 first grows later
    python benchmarks/reach_study.py table study/runs --design study/design.csv --out study/
    python benchmarks/reach_study.py figure study/draws.csv --out docs/figures/reach_region.png

``design`` draws the declared prior (``benchmarks/reach_prior.toml``) as a scrambled Sobol design
(:mod:`neurocur.experiments.design`), each draw a condition of one experiment extending
``synthetic`` with paired runs.
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import pandas as pd

from neurocur.experiments.design import design_experiment, read_prior
from neurocur.results.safeio import atomic_text
from neurocur.results.tomlio import dumps_toml

PRIOR = Path(__file__).with_name("reach_prior.toml")
#: the declared size and seeds (section 2.11)
DRAWS, RUNS, STEPS, SEED, DESIGN_SEED = 64, 16, 350_000, 6001, 6002


def design(out: Path, prior_path: Path = PRIOR, *, n: int = DRAWS, runs: int = RUNS, steps: int = STEPS) -> Path:
    """Write ``out/reach.toml`` (the experiment) and ``out/design.csv`` (one row per draw)."""
    prior = read_prior(tomllib.loads(prior_path.read_text())["prior"], source=prior_path)
    table = design_experiment("synthetic", prior, n=n, runs=runs, steps=steps, seed=SEED, design_seed=DESIGN_SEED,
                              name="reach", description="Draws of the open choices' prior (docs/reproduction.md, 2.11).")
    out.mkdir(parents=True, exist_ok=True)
    atomic_text(out / "reach.toml", dumps_toml(table, header="Written by benchmarks/reach_study.py design"))
    rows = [{"condition": name, **{k: c.get("params", {}).get(k, c.get("world", {}).get(k.removeprefix("world.")))
                                   for k in prior if k != "circuit"}, "circuit": c.get("circuit")}
            for name, c in table["conditions"].items()]
    atomic_text(out / "design.csv", pd.DataFrame(rows).to_csv(index=False))
    return out / "reach.toml"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("design")
    p.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    if args.command == "design":
        print(design(args.out))


if __name__ == "__main__":
    main()
