"""Which source the agent learns second, and what its reward said in that cycle (a study of
results folders, not a test; docs/reproduction.md, section 2.9).

    neurocur run synthetic --condition curious --seed 2026 --out results/s2026   # and more seed sets
    python benchmarks/second_cycle_study.py results/s2026 results/s2013 results/s7

Pools the runs of one condition of the given folders and prints the orders in which the
learnable sources were first stored, then, over the runs whose first module is the easiest
source (S-A) and whose second is S-B or S-C, the second cycle (after the first storage, up to
and including the second):

- the mean DA of each candidate source's unfamiliar episodes, compared paired by run (Wilcoxon
  signed-rank), and how often the source that paid more was the one stored second (a two-sided
  binomial test at 1/2);
- the runs in which a frozen module gated an episode of each candidate source as familiar (the
  −100 boredom reward, section 3.2 of the paper), by the source stored second (Fisher's exact test).
"""

from __future__ import annotations

import argparse

import pandas as pd
from scipy.stats import binomtest

from neurocur.analysis import Results, load, per_run, source_specs, wilcoxon_signed_rank
from neurocur.analysis.stats.significance import fisher_exact


def second_cycles(folders: list[str], condition: str) -> tuple[pd.Series, pd.DataFrame]:
    """The order counts, and one row per run with S-A first and S-B or S-C second."""
    orders, rows = [], []
    for folder in folders:
        episodes, modules = load(folder)
        spec = source_specs(folder)[condition]
        easiest, b, c = spec.learnable
        contexts = {s: [i for i, name in enumerate(spec.context_sources) if name == s] for s in (b, c)}
        runs = per_run(Results.of(episodes, modules, spec))
        runs = runs[runs["condition"] == condition]
        orders += [" → ".join(dict.fromkeys(s for s in o.split(",") if s in spec.learnable)) or "(none)"
                   for o in runs["order"]]
        mods = modules[modules["condition"] == condition].sort_values("module")
        eps = episodes[episodes["condition"] == condition]
        for run, stored in mods.groupby("run"):
            if len(stored) < 2 or stored["source"].iloc[0] != easiest or stored["source"].iloc[1] not in (b, c):
                continue
            start, end = stored["step"].iloc[:2]
            cycle = eps[(eps["run"] == run) & (eps["step"] > start) & (eps["step"] <= end)]
            row = {"folder": folder, "run": run, "second": stored["source"].iloc[1]}
            for s, where in contexts.items():
                here = cycle[cycle["context"].isin(where)]
                row[f"da_{s}"] = here.loc[~here["familiar"], "da"].mean()
                row[f"familiar_{s}"] = bool(here["familiar"].any())
            rows.append(row)
    return pd.Series(orders).value_counts(), pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folders", nargs="+", help="results folders (pooled)")
    parser.add_argument("--condition", default="curious")
    args = parser.parse_args()
    orders, table = second_cycles(args.folders, args.condition)
    print(f"orders of the learnable sources' first modules ({orders.sum()} runs):\n{orders.to_string()}\n")
    b, c = (col[3:] for col in table.columns if col.startswith("da_"))
    print(f"{len(table)} runs with S-A first and {b} or {c} second: {table['second'].value_counts().to_dict()}")
    paid = table.dropna(subset=[f"da_{b}", f"da_{c}"])
    test = wilcoxon_signed_rank(paid[f"da_{b}"], paid[f"da_{c}"])
    print(f"second cycle, mean DA of the unfamiliar episodes: {b} {paid[f'da_{b}'].mean():.3f} "
          f"(median run {paid[f'da_{b}'].median():.3f}), {c} {paid[f'da_{c}'].mean():.3f} "
          f"(median run {paid[f'da_{c}'].median():.3f}); {test['test']}, p = {test['p_value']:.3g}")
    agree = int(((paid[f"da_{b}"] > paid[f"da_{c}"]) == (paid["second"] == b)).sum())
    print(f"the source that paid more was stored second in {agree}/{len(paid)} runs, "
          f"binomial p = {binomtest(agree, len(paid)).pvalue:.3g}")
    for s in (b, c):
        by = [table.loc[table["second"] == x, f"familiar_{s}"] for x in (b, c)]
        test = fisher_exact(*by)
        print(f"runs with an episode of {s} gated as familiar in the cycle: {int(by[0].sum())}/{len(by[0])} "
              f"when {b} came second, {int(by[1].sum())}/{len(by[1])} when {c} did; {test['test']}, "
              f"p = {test['p_value']:.3g}")


if __name__ == "__main__":
    main()
