"""When does a module converge, and when does the freeze rule say it has? (a study, not a test)

    python benchmarks/learning_time_study.py single [--seeds 5] [--epochs 60]
    python benchmarks/learning_time_study.py full [--seeds 4] [--steps 350000]
    python benchmarks/learning_time_study.py progress [--seeds 20]
    python benchmarks/learning_time_study.py ... --set HPC.threshold=0.1 EC.mca_rate=0.02

Both modes build the synthetic experiment's condition ``curious`` as ``neurocur run`` does
(``neurocur/experiments_data/synthetic.toml``: its circuit, the experiment's parameters and the
condition's; ``--set`` overrides them) and follow the adaptive module episode by episode. Its **quality** for a source is
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

``progress``: what the reward pays for learning each source, with nothing ever stored (threshold
0), as the mean DA (VTA's output) per episode up to a number of epochs of the source's frames.
Staying: one context per source, the agent always stays (as in ``single``). Switching: one
context per source and S-D, the agent engages or switches at random (the LC's ``random``
lesion). Printed per mode and epoch mark: the mean DA per source over seeds, and S-A against
S-B and S-B against S-C, paired by seed (how often the easier paid more; Wilcoxon signed-rank).
"""

from __future__ import annotations

import argparse
import math

import numpy as np
import pandas as pd

from neurocur.analysis import wilcoxon_signed_rank
from neurocur.circuit import Circuit
from neurocur.contexts.sources import SLOW_DIM
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.experiments import load_experiment
from neurocur.learn.correlation import abs_corr
from neurocur.regions.hpc import extrapolated_drift
from neurocur.regions.lc import EpsilonGreedyLC
from neurocur.regions.pfc import ENGAGE

EPOCH = 1000
THRESHOLDS = (0.3, 0.15, 0.08)
LEVELS = (0.99, 0.999)
MARKS = (2, 5, 10, 20)  # epochs of a source's frames at which ``progress`` averages its DA
SOURCES = ("S-A", "S-B", "S-C")


class StayLC(EpsilonGreedyLC):
    """Always engage: the agent stays in its first context."""

    def step(self, context, q, module_learned):
        self._rec = (ENGAGE, context, 0.0, 0.0, 0.0)
        return ENGAGE, context, 0.0


def curious(sets: list[str], *, never_store: bool = False) -> tuple[dict, Circuit]:
    """The synthetic experiment's world settings (but its contexts) and circuit of condition ``curious``,
    with ``--set``; ``never_store``: a freeze threshold of 0 and the first context first, so the
    adaptive module of the context the run starts in keeps learning."""
    condition = load_experiment("synthetic", sets=sets).conditions["curious"]
    world = {k: v for k, v in condition.world.items() if k not in ("type", "contexts", "context_names")}
    circuit = condition.circuit
    if never_store:
        circuit = circuit.with_params({"HPC.threshold": 1e-300, "sensory.initial_context": 0})
    return world, circuit


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
    world_kw, circuit = curious(sets, never_store=True)
    rows = []
    for source in SOURCES:
        for seed in range(seeds):
            world = SyntheticWorld(contexts=[source, "S-D"], **world_kw)
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
    world_kw, circuit = curious(sets)
    contexts = ["S-A", "S-A", "S-B", "S-C", "S-D"]
    rows = []
    for seed in range(seeds):
        world = SyntheticWorld(contexts=contexts, **world_kw)
        sim = circuit.build(world, seed=seed)
        ec, hpc = sim.regions["EC"], sim.regions["HPC"]
        spent = dict.fromkeys(SOURCES, 0)
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
                spent = dict.fromkeys(SOURCES, 0)
                reached = {}
                continue
            if src in SOURCES:
                q = quality(ec.adaptive, world, ctx)
                for lv in LEVELS:
                    if q >= lv and (src, lv) not in reached:
                        reached[(src, lv)] = spent[src] / EPOCH
    return pd.DataFrame(rows)


def paid(circuit: Circuit, world: SyntheticWorld, seed: int, epochs: int) -> pd.DataFrame:
    """One row per pass: the frames of each context before it, its context and the DA it released."""
    sim = circuit.build(world, seed=seed)
    seen = np.zeros(world.n_contexts, dtype=int)
    learnable = [c for c in range(world.n_contexts) if world.source_of(c) in SOURCES]
    rows = []
    while seen[learnable].min() < epochs * EPOCH:
        before = sim.n_frames
        sim.run(1)
        context = sim.regions["HPC"]._context
        rows.append((world.source_of(context), seen[context], sim.regions["VTA"].da))
        seen[context] += sim.n_frames - before
    return pd.DataFrame(rows, columns=["source", "frames_before", "da"])


def progress(seeds: int, sets: list[str]) -> pd.DataFrame:
    world_kw, circuit = curious(sets, never_store=True)
    modes = {"staying": circuit.replace("LC", StayLC("LC")), "switching": circuit.lesion("LC", "random")}
    rows = []
    for seed in range(seeds):
        for mode, built in modes.items():
            worlds = ([[s, "S-D"] for s in SOURCES] if mode == "staying" else [[*SOURCES, "S-D"]])
            trace = pd.concat([paid(built, SyntheticWorld(contexts=c, **world_kw), seed, MARKS[-1]) for c in worlds])
            for mark in MARKS:
                early = trace[trace["frames_before"] < mark * EPOCH]
                for source, da in early[early["source"].isin(SOURCES)].groupby("source")["da"]:
                    rows.append({"mode": mode, "epochs": mark, "seed": seed, "source": source, "da": da.mean()})
    return pd.DataFrame(rows)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=("single", "full", "progress"))
    parser.add_argument("--seeds", type=int, default=None, help="runs (default: 5 single, 4 full, 20 progress)")
    parser.add_argument("--epochs", type=int, default=60, help="single: epochs per source")
    parser.add_argument("--steps", type=int, default=350_000, help="full: frames per run")
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE", help="override a setting")
    args = parser.parse_args(argv)
    with pd.option_context("display.width", 250, "display.max_columns", None, "display.float_format", "{:.3g}".format):
        if args.mode == "single":
            table = single(args.seeds or 5, args.epochs, args.set)
            print(table.to_string(index=False))
            print(table.drop(columns="seed").groupby("source").median().T.to_string())
        elif args.mode == "progress":
            table = progress(args.seeds or 20, args.set)
            means = table.pivot_table(index=["mode", "epochs"], columns="source", values="da")
            for (mode, mark), g in table.groupby(["mode", "epochs"]):
                pair = g.pivot(index="seed", columns="source", values="da")
                for a, b in zip(SOURCES, SOURCES[1:]):
                    means.loc[(mode, mark), f"{a} > {b}"] = f"{int((pair[a] > pair[b]).sum())}/{len(pair)}"
                    means.loc[(mode, mark), f"p ({a} vs {b})"] = wilcoxon_signed_rank(pair[a], pair[b])["p_value"]
            print(means.to_string())
        else:
            table = full(args.seeds or 4, args.steps, args.set)
            print(table.to_string(index=False))
            print(table.groupby("source")[["epochs", "quality", *[f"q>={lv}" for lv in LEVELS]]].median().to_string())


if __name__ == "__main__":
    main()
