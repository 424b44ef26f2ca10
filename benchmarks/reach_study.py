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
import itertools
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

from neurocur.analysis import Results, learning_times, per_run
from neurocur.analysis.stats.order import clopper_pearson
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


#: the paper's point (section 4.1.1, 4.1.4; docs/reproduction.md, section 2.2): counts of 25 runs, times in epochs
PAPER_COUNTS = {"S-A first": 25, "exact order": 18, "S-D stored": 0}
PAPER_TIMES = {"S-A": (2.0, 3.0), "S-B": (15.0, 15.0), "S-C": (40.0, 40.0)}
SHARES = {"S-A first": "first_ok", "exact order": "exact_order", "S-D stored": "unlearnable_stored",
          "all three learned": "all_three"}


def draw_statistics(results: Results) -> pd.DataFrame:
    """One row per draw (condition): runs, the counts of :data:`SHARES`, and the median learning time
    (epochs) of each learnable source's first module over the runs that stored it, with that number."""
    runs = per_run(results).assign(all_three=lambda t: t["n_learned"] == 3)
    times = learning_times(results)
    times = times[times["learnable"] & times["first_of_source"]]
    rows = []
    for condition, table in runs.groupby("condition", sort=True):
        row = {"condition": condition, "runs": len(table)}
        row.update({name: int(table[column].sum()) for name, column in SHARES.items()})
        for source in PAPER_TIMES:
            t = times.loc[(times["condition"] == condition) & (times["source"] == source), "epochs"]
            row[f"{source} time"] = float(t.median()) if len(t) else np.nan
            row[f"{source} learned"] = len(t)
        rows.append(row)
    return pd.DataFrame(rows)


def bounds() -> dict[str, tuple[float, float]]:
    """The rule's box on each statistic (shares of the runs; epochs): the 95 % Clopper–Pearson
    interval of the paper's count out of 25, one-sided (at least the lower end for S-A first and
    the exact order, at most the upper end for S-D stored), and within 2× of the paper's times."""
    box = {"S-A first": (clopper_pearson(25, 25)[0], 1.0), "exact order": (clopper_pearson(18, 25)[0], 1.0),
           "S-D stored": (0.0, clopper_pearson(0, 25)[1])}
    box.update({f"{s} time": (low / 2, high * 2) for s, (low, high) in PAPER_TIMES.items()})
    return box


def criteria(stats: pd.DataFrame) -> pd.DataFrame:
    """Which of the rule's six criteria each draw meets (:func:`bounds`; a time never measured fails)."""
    met = {}
    for name, (low, high) in bounds().items():
        value = stats[name] if name.endswith("time") else stats[name] / stats["runs"]
        met[name] = (value >= low - 1e-12) & (value <= high + 1e-12)
    table = pd.DataFrame(met, index=stats.index)
    return table.assign(met=table.sum(axis=1), reached=table.all(axis=1))


def pairs(met: pd.DataFrame) -> pd.DataFrame:
    """Draws meeting each criterion (diagonal) and each pair of criteria (off the diagonal)."""
    names = list(bounds())
    table = pd.DataFrame(0, index=names, columns=names)
    for a, b in itertools.product(names, names):
        table.loc[a, b] = int((met[a] & met[b]).sum())
    return table


def correlations(stats: pd.DataFrame) -> pd.DataFrame:
    """Spearman's ρ across draws between the statistics (shares and median times), with p."""
    values = stats.assign(**{n: stats[n] / stats["runs"] for n in SHARES})
    names = [*SHARES, *(f"{s} time" for s in PAPER_TIMES)]
    rows = []
    for a, b in itertools.combinations(names, 2):
        x = values[[a, b]].dropna()
        varies = len(x) > 2 and x[a].nunique() > 1 and x[b].nunique() > 1
        rho, p = spearmanr(x[a], x[b]) if varies else (np.nan, np.nan)
        rows.append({"a": a, "b": b, "n": len(x), "rho": rho, "p": p})
    return pd.DataFrame(rows)


def figure(stats: pd.DataFrame, out: Path) -> None:
    """Pairwise scatters of the per-draw statistics, the rule's box shaded and the paper's point marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = ["S-A first", "exact order", "S-D stored", "S-A time", "S-B time", "S-C time"]
    values = stats.assign(**{n: stats[n] / stats["runs"] for n in SHARES})
    paper = {"S-A first": 1.0, "exact order": 18 / 25, "S-D stored": 0.0, "S-A time": 2.5, "S-B time": 15.0,
             "S-C time": 40.0}
    box, met = bounds(), criteria(stats)["met"]
    label = {n: n + ("\n(epochs, median)" if n.endswith("time") else "\n(share of runs)") for n in names}
    fig, axes = plt.subplots(len(names) - 1, len(names) - 1, figsize=(12, 12))
    for i, j in itertools.product(range(1, len(names)), range(len(names) - 1)):
        ax = axes[i - 1, j]
        if j >= i:
            ax.axis("off")
            continue
        x, y = names[j], names[i]
        ax.add_patch(plt.Rectangle((box[x][0], box[y][0]), box[x][1] - box[x][0], box[y][1] - box[y][0],
                                   color="tab:green", alpha=0.2, lw=0))
        points = ax.scatter(values[x], values[y], c=met, cmap="viridis", vmin=0, vmax=6, s=16)
        ax.plot(paper[x], paper[y], marker="*", color="tab:red", ms=13, ls="")
        for name, axis in ((x, "x"), (y, "y")):
            if name.endswith("time"):
                getattr(ax, f"set_{axis}scale")("log")
                getattr(ax, f"set_{axis}lim")(0.8, 100)
            else:
                getattr(ax, f"set_{axis}lim")(-0.05, 1.05)
        ax.tick_params(labelsize=8, labelbottom=i == len(names) - 1, labelleft=j == 0)
        if i == len(names) - 1:
            ax.set_xlabel(label[x], fontsize=9)
        if j == 0:
            ax.set_ylabel(label[y], fontsize=9)
    fig.colorbar(points, cax=axes[0, -1].inset_axes([0.1, 0.0, 0.08, 1.0]), label="criteria met (of 6)")
    axes[1, -1].text(0.0, 1.0, f"{len(stats)} readings drawn from the open\nchoices' prior (Sobol), "
                     f"{int(stats['runs'].min())}–{int(stats['runs'].max())} paired\nruns of 3.5·10⁵ frames each\n\n"
                     "red star: the paper's point\ngreen: the declared rule's box\n(Clopper–Pearson ends of the\n"
                     "paper's counts; times within 2×)", va="top", fontsize=10, transform=axes[1, -1].transAxes)
    fig.subplots_adjust(hspace=0.08, wspace=0.08)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90, bbox_inches="tight")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("design")
    p.add_argument("--out", type=Path, required=True)
    p = sub.add_parser("table")
    p.add_argument("runs", type=Path)
    p.add_argument("--design", type=Path, required=True)
    p.add_argument("--out", type=Path, required=True)
    p = sub.add_parser("figure")
    p.add_argument("draws", type=Path)
    p.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    if args.command == "design":
        print(design(args.out))
    elif args.command == "table":
        stats = draw_statistics(Results.load(args.runs))
        met = criteria(stats)
        table = pd.read_csv(args.design).merge(pd.concat([stats, met], axis=1), on="condition")
        args.out.mkdir(parents=True, exist_ok=True)
        atomic_text(args.out / "draws.csv", table.to_csv(index=False))
        print(stats.assign(met=met["met"], reached=met["reached"]).to_string(index=False))
        print("\ndraws meeting each criterion (diagonal) and each pair:")
        print(pairs(met).to_string())
        print("\nSpearman's rho across draws:")
        print(correlations(stats).to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    else:
        figure(pd.read_csv(args.draws), args.out)


if __name__ == "__main__":
    main()
