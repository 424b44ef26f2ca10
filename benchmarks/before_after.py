"""Paired statistics of one experiment run twice on the same seeds: before and after a code change.

    python benchmarks/before_after.py BEFORE_DIR AFTER_DIR [BEFORE_DIR AFTER_DIR ...] [--condition curious ...]

A change that alters the results tables for the same seeds is shown with this table in
its commit message and in ``docs/reproduction.md``. For every condition present in both
folders, run i of BEFORE and run i of AFTER share their seed, so they are compared
paired by run: the order metrics by :func:`neurocur.analysis.stats.comparison.compare`
(Wilcoxon signed-rank for numbers, McNemar's exact test for yes/no) and the efficiency
metrics by :func:`neurocur.analysis.stats.efficiency.compare_efficiency`, Holm-adjusted over all
the metrics of a condition. The mean learning time of each source's first module
(epochs, Figure 4F) follows, tested (Wilcoxon) on the runs that learned the source both
times; ``n_pairs`` counts them. Several pairs of folders (e.g. one per seed set) are pooled:
the runs of the k-th pair are numbered from 1000·k.
"""

from __future__ import annotations

import argparse

import pandas as pd

from neurocur.analysis import (
    Results,
    adjust_pvalues,
    compare,
    compare_efficiency,
    efficiency_per_run,
    learning_times,
    load,
    per_run,
    source_specs,
    wilcoxon_signed_rank,
)
from neurocur.analysis.stats.order import BINARY_METRICS, NUMERIC_METRICS


def relabelled(tables, condition: str, label: str):
    """The (episodes, modules) of one condition of a loaded folder, its condition renamed ``label``."""
    episodes, modules = (t[t["condition"] == condition].assign(condition=label) for t in tables)
    return episodes, modules


def condition_table(before, after, condition: str, spec) -> pd.DataFrame:
    """The paired before/after rows of one condition of the loaded folders ``before`` and
    ``after`` ((episodes, modules) each): metric, before, after, difference [CI], p, p (Holm)."""
    pairs = [relabelled(before, condition, "before"), relabelled(after, condition, "after")]
    results = Results.of(*(pd.concat(t, ignore_index=True) for t in zip(*pairs)), spec)
    rows = pd.concat([
        compare(per_run(results), "after", "before", [*NUMERIC_METRICS, *BINARY_METRICS], adjust=None),
        compare_efficiency(efficiency_per_run(results), "after", "before", adjust=None),
    ], ignore_index=True)
    times = learning_times(results).query("learnable and first_of_source")
    by_run = times.pivot_table(index="run", columns=["source", "condition"], values="epochs")
    for source in sorted(times["source"].unique()):
        a, b = by_run.get((source, "after")), by_run.get((source, "before"))
        both = by_run[[(source, "after"), (source, "before")]].dropna() if a is not None and b is not None else None
        test = wilcoxon_signed_rank(both.iloc[:, 0], both.iloc[:, 1]) if both is not None and len(both) else {}
        rows.loc[len(rows), ["metric", "value_a", "value_b", "difference", "n_pairs", "p_value"]] = [
            f"learning time {source} (epochs, first module)",
            a.mean() if a is not None else float("nan"), b.mean() if b is not None else float("nan"),
            (both.iloc[:, 0] - both.iloc[:, 1]).mean() if both is not None else float("nan"),
            len(both) if both is not None else 0, test.get("p_value", float("nan"))]
    rows = adjust_pvalues(rows, "holm")
    return rows.assign(condition=condition)


def pooled(folders: list[str]):
    """The (episodes, modules) of ``folders`` loaded and concatenated, the k-th folder's runs numbered from 1000·k."""
    tables = [[t.assign(run=t["run"] + 1000 * k) for t in load(folder)] for k, folder in enumerate(folders)]
    return tuple(pd.concat(t, ignore_index=True) for t in zip(*tables))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", metavar="BEFORE AFTER",
                        help="a results folder computed by the code before the change, then one of the same "
                             "experiment and seeds after it; more such pairs are pooled")
    parser.add_argument("--condition", action="append", help="only this condition (repeatable; default: all shared)")
    args = parser.parse_args(argv)
    if len(args.folders) % 2:
        parser.error(f"expected pairs of folders (BEFORE AFTER ...), got {len(args.folders)} folders")
    befores, afters = args.folders[0::2], args.folders[1::2]
    specs, before_specs = source_specs(afters[0]), source_specs(befores[0])
    conditions = args.condition or [c for c in specs if c in before_specs]
    before, after = pooled(befores), pooled(afters)
    columns = {"condition": "condition", "metric": "metric", "value_b": "before", "value_a": "after",
               "difference": "after − before", "ci_diff_low": "CI low", "ci_diff_high": "CI high",
               "n_pairs": "pairs", "p_value": "p", "p_adjusted": "p (Holm)"}
    table = pd.concat([condition_table(before, after, c, specs[c]) for c in conditions], ignore_index=True)
    table = table[list(columns)].rename(columns=columns)
    with pd.option_context("display.width", 250, "display.max_columns", None, "display.max_rows", None,
                           "display.float_format", "{:.4g}".format):
        print(table.to_string(index=False))


if __name__ == "__main__":
    main()
