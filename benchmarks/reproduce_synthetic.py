"""Print the reproduction study's main table from a results folder.

    neurocur run experiments/reproduction.toml --out results/reproduction
    python benchmarks/reproduce_synthetic.py results/reproduction [--markdown]

One row per condition: the module-order counts (S-A first, S-B second, S-C third,
exact A→B→C, S-D stored), modules and gated learnable sources per run, Kendall τ
against the Ω order, then the curious-versus-random comparison on gated sources for
every condition that has a random-switching twin: Mann–Whitney U p-value and
rank-biserial effect size. A condition's twin is ``<name>_random``; a condition that
differs from another only in what the random LC never reads (the reward, its model and
the discount: ``HPC.reward_error``, ``VTA.*``, ``PFC.*``) shares that one's twin, by
the paired seeds its runs are the same (see ``SHARED_CONTROLS``).
"""

from __future__ import annotations

import argparse

import pandas as pd

from neurocur.analysis import compare, load, order_table, per_run

PAPER_ROW = {"S-A first": "25/25", "S-B second": "18/25", "S-C third": "18/25", "exact S-A→S-B→S-C": "18/25",
             "S-D stored": "0/25", "modules per run": "3", "learnable sources gated": "3",
             "Kendall τ vs Ω": "0.81", "gated vs random: p": "—", "effect (rank-biserial)": "—"}
COLUMNS = list(PAPER_ROW)
SHARED_CONTROLS = {
    "reward_episode": "default_random", "alpha_005": "default_random", "alpha_05": "default_random",
    "discount_05": "default_random", "discount_099": "default_random", "no_boredom": "default_random",
    "norm_image": "chosen_random", "reward_episode_discount": "default_random",
}


def study_table(results_dir) -> pd.DataFrame:
    """Conditions × statistics, the paper's row first."""
    episodes, modules = load(results_dir)
    table = order_table(episodes, modules).drop(columns=["paper", "paper (random)"]).T
    runs = per_run(episodes, modules)
    conditions = list(table.index)
    for name in conditions:
        twin = SHARED_CONTROLS.get(name, f"{name}_random")
        if twin in conditions:
            row = compare(runs, a=name, b=twin, metric="gated_sources").iloc[0]
            table.loc[name, "gated vs random: p"] = f"{row.p_value:.2g}"
            table.loc[name, "effect (rank-biserial)"] = f"{row.effect_size:+.2f}"
    table = table.reindex(columns=COLUMNS).fillna("—")
    return pd.concat([pd.DataFrame([PAPER_ROW], index=["paper"]), table])


def markdown(table: pd.DataFrame) -> str:
    """``table`` as a GitHub Markdown table (index as the first column)."""
    head = ["condition", *table.columns]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join([str(i), *map(str, row)]) + " |" for i, row in zip(table.index, table.values)]
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="results folder of experiments/reproduction.toml")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = parser.parse_args(argv)
    table = study_table(args.results)
    with pd.option_context("display.width", 250, "display.max_columns", None):
        print(markdown(table) if args.markdown else table.to_string())


if __name__ == "__main__":
    main()
