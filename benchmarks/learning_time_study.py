"""When does a module converge, and when does the freeze rule say it has? (a study, not a test)

    python benchmarks/learning_time_study.py single [--seeds 5] [--epochs 60]
    python benchmarks/learning_time_study.py full [--seeds 4] [--steps 350000]
    python benchmarks/learning_time_study.py ... --set HPC.threshold=0.1 EC.mca_rate=0.02

Both modes build the synthetic experiment's circuit with its parameters
(``neurocur/experiments_data/synthetic.toml``, condition ``curious``; ``--set`` overrides
them) and follow the adaptive module episode by episode. Its **quality** for a source is
the |corr| of its slowest output, on one epoch of the source's frames, with the source's
slow dimension (what ``module_report`` gives a stored module).

``single``: one context per source (S-A, S-B, S-C), the agent always stays, and nothing is
ever stored (the freeze threshold is set to 0, so the module keeps learning). After every
episode the HPC's state gives the error of each freeze rule at that moment: the
context-mean stored error (``context_mean``) and the extrapolated remaining drift
(``converged``). Printed per source: the epochs until the quality first reaches 0.99 and
0.999 (and stays there to the end), against the epochs until each rule would first fire at
thresholds 0.3, 0.15 and 0.08, with the quality at that moment (median over seeds).

``full``: the curious agent in the five-context world, unchanged. Printed per stored
module: its source, the epochs it spent in its source's contexts since the previous
storage (Figure 4F's learning time), its quality at storage, and the epochs after which its
quality for that source had first reached 0.99 and 0.999 (NaN: never before storage).
"""

from __future__ import annotations

import argparse
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from neurocur.circuit import Circuit
from neurocur.contexts.sources import SLOW_DIM
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.experiments.sets import parse_set
from neurocur.learn.correlation import abs_corr
from neurocur.regions.hpc import extrapolated_drift
from neurocur.regions.lc import EpsilonGreedyLC
from neurocur.regions.pfc import ENGAGE

ROOT = Path(__file__).resolve().parents[1] / "neurocur"
EPOCH = 1000
THRESHOLDS = (0.3, 0.15, 0.08)
LEVELS = (0.99, 0.999)


class StayLC(EpsilonGreedyLC):
    """Always engage: the agent stays in its first context."""

    def step(self, context, q, module_learned):
        self._rec = (ENGAGE, context, 0.0, 0.0, 0.0)
        return ENGAGE, context, 0.0


def experiment_params(sets: list[str]) -> tuple[dict, dict]:
    """The synthetic experiment's (world, circuit-param) settings of condition ``curious``, plus ``--set``."""
    spec = tomllib.loads((ROOT / "experiments_data" / "synthetic.toml").read_text())
    world = {k: v for k, v in spec["world"].items() if k not in ("type", "contexts", "context_names")}
    params = dict(spec["params"])
    for key, value in map(parse_set, sets):
        (world if key.startswith("world.") else params)[key.removeprefix("world.")] = value
    return world, params


def quality(model, world: SyntheticWorld, context: int) -> float:
    """|corr| of the module's slowest output on one epoch of ``context`` with its slow dimension."""
    if not model.__sklearn_is_fitted__() or model.n_active_ == 0:
        return 0.0
    y = model.transform(world.context_frames(context))[:, 0]
    q = abs_corr(y, world.source_signal(world.source_of(context))[:, SLOW_DIM])
    return 0.0 if math.isnan(q) else q


def first_epoch(frames: np.ndarray, ok: np.ndarray) -> float:
    """Epochs (frames / 1000) at the first episode from which ``ok`` holds to the end; NaN if never."""
    if not ok.any() or not ok[-1]:
        return np.nan
    bad = np.flatnonzero(~ok)
    start = 0 if len(bad) == 0 else bad[-1] + 1
    return frames[start] / EPOCH


def single(seeds: int, epochs: int, sets: list[str]) -> pd.DataFrame:
    world_kw, params = experiment_params(sets)
    rows = []
    for source in ("S-A", "S-B", "S-C"):
        for seed in range(seeds):
            world = SyntheticWorld(contexts=[source, "S-D"], **world_kw)
            circuit = Circuit.from_toml(ROOT / "circuits" / "cd_misfa.toml",
                                        overrides={**params, "HPC.threshold": 1e-300, "sensory.initial_context": 0})
            sim = circuit.replace("LC", StayLC("LC")).build(world, seed=seed)
            hpc, ec = sim.regions["HPC"], sim.regions["EC"]
            trace = []
            while sim.n_frames < epochs * EPOCH:
                sim.run(1)
                row = hpc.stored[0]
                known = ~np.isnan(row)
                mean = row[known].mean() if known.all() else np.inf
                drift = extrapolated_drift(hpc.history[:, 0]) if known.all() else np.inf
                if hpc.params.ordered and not hpc.ordered(0):  # the variant's check vetoes both rules
                    mean = drift = np.inf
                trace.append((sim.n_frames, quality(ec.adaptive, world, 0), mean, drift))
            frames, q, mean, drift = map(np.array, zip(*trace))
            out = {"source": source, "seed": seed}
            for level in LEVELS:
                out[f"q>={level}"] = first_epoch(frames, q >= level)
            for name, err in (("context_mean", mean), ("converged", drift)):
                for th in THRESHOLDS:
                    hit = np.flatnonzero(err < th)
                    out[f"{name}<{th}"] = frames[hit[0]] / EPOCH if len(hit) else np.nan
                    out[f"q at {name}<{th}"] = q[hit[0]] if len(hit) else np.nan
            out["q end"] = q[-1]
            rows.append(out)
    return pd.DataFrame(rows)


def full(seeds: int, steps: int, sets: list[str]) -> pd.DataFrame:
    world_kw, params = experiment_params(sets)
    contexts = ["S-A", "S-A", "S-B", "S-C", "S-D"]
    rows = []
    for seed in range(seeds):
        world = SyntheticWorld(contexts=contexts, **world_kw)
        sim = Circuit.from_toml(ROOT / "circuits" / "cd_misfa.toml", overrides=params).build(world, seed=seed)
        ec, hpc = sim.regions["EC"], sim.regions["HPC"]
        learnable = ("S-A", "S-B", "S-C")
        spent = dict.fromkeys(learnable, 0)
        reached = {}
        while sim.n_frames < steps:
            before, n_lib = sim.n_frames, len(hpc.library)
            model = ec.adaptive
            sim.run(1)
            ctx = hpc._context
            src = world.source_of(ctx)
            if src in spent:
                spent[src] += sim.n_frames - before
            if len(hpc.library) > n_lib:  # stored at this episode: the stored module is `model`
                q = quality(model, world, ctx)
                rows.append({"seed": seed, "module": n_lib, "source": src, "epochs": spent.get(src, np.nan) / EPOCH,
                             "quality": q, **{f"q>={lv}": reached.get((src, lv), np.nan) for lv in LEVELS}})
                spent = dict.fromkeys(learnable, 0)
                reached = {}
                continue
            if src in learnable:
                q = quality(ec.adaptive, world, ctx)
                for lv in LEVELS:
                    if q >= lv and (src, lv) not in reached:
                        reached[(src, lv)] = spent[src] / EPOCH
    return pd.DataFrame(rows)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=("single", "full"))
    parser.add_argument("--seeds", type=int, default=None, help="runs (default: 5 single, 4 full)")
    parser.add_argument("--epochs", type=int, default=60, help="single: epochs per source")
    parser.add_argument("--steps", type=int, default=350_000, help="full: frames per run")
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE", help="override a setting")
    args = parser.parse_args(argv)
    with pd.option_context("display.width", 250, "display.max_columns", None, "display.float_format", "{:.3g}".format):
        if args.mode == "single":
            table = single(args.seeds or 5, args.epochs, args.set)
            print(table.to_string(index=False))
            print(table.drop(columns="seed").groupby("source").median().T.to_string())
        else:
            table = full(args.seeds or 4, args.steps, args.set)
            print(table.to_string(index=False))
            print(table.groupby("source")[["epochs", "quality", *[f"q>={lv}" for lv in LEVELS]]].median().to_string())


if __name__ == "__main__":
    main()
