"""Where the iCub agent spends its frames after its first stored module, and why (a study of
results folders, not a test; docs/reproduction.md, section 3, "Why the curious agent keeps to
roll after its first module").

    neurocur run icub --out results/icub                        # and --seed 7, --seed 11
    python benchmarks/icub_roll_study.py results/icub results/icub_s7 results/icub_s11

Pools the runs of the given folders and splits each at the episode that stored its first
module. Printed per condition and first stored object, over the episodes after that one: the
runs, the share of frames in roll (median over runs, :func:`neurocur.analysis.share_after`),
the share of topple's and of roll's episodes gated as familiar (pooled over runs; a gated
episode pays the −100 boredom reward), the share of the decisions in roll that engaged and ε
(medians over runs), the mean DA of roll's unfamiliar episodes (median over runs), and the runs
that learned both objects. Then the share of frames in roll before the first storage (median
over runs, per folder).
"""

from __future__ import annotations

import argparse

import pandas as pd

from neurocur.analysis import load, source_specs
from neurocur.analysis.stats.dwell import share_after


def after_first_module(folders: list[str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """One row per run that stored a module (the numbers after its first storage), and one row
    per (folder, condition): the share of frames in roll before it (median over runs)."""
    rows, before = [], []
    for folder in folders:
        episodes, modules = load(folder)
        spec = source_specs(folder)
        first = modules.sort_values("module").groupby(["condition", "run"], as_index=False).first()
        after = share_after(episodes, "roll", first[["condition", "run", "episode"]], spec=spec)
        after = after.set_index(["condition", "run"])
        whole = share_after(episodes, "roll", spec=spec).set_index(["condition", "run"])
        share_before = ((whole["frames_in"] - after["frames_in"].fillna(0))
                        / (whole["frames_after"] - after["frames_after"].fillna(0)))
        before += [{"folder": folder, "condition": c, "roll_share_before": v}
                   for c, v in share_before.groupby(level="condition").median().items()]
        for m in first.itertuples(index=False):
            names = spec[m.condition].context_names
            eps = episodes[(episodes["condition"] == m.condition) & (episodes["run"] == m.run)]
            later = eps[eps["episode"] > m.episode]
            topple = later[later["context"] == names.index("topple")]
            roll = later[later["context"] == names.index("roll")]
            stored = set(modules[(modules["condition"] == m.condition) & (modules["run"] == m.run)]["source"])
            rows.append({"condition": m.condition, "run": m.run, "first": m.source,
                         "roll_share": after.loc[(m.condition, m.run), "share"],
                         "topple_gated": int(topple["familiar"].sum()), "topple_episodes": len(topple),
                         "roll_gated": int(roll["familiar"].sum()), "roll_episodes": len(roll),
                         "engage_in_roll": float((roll["action"].astype(str) == "engage").mean()),
                         "epsilon": float(later["epsilon"].median()),
                         "roll_da": float(roll.loc[~roll["familiar"].astype(bool), "da"].mean()),
                         "both": {"topple", "roll"} <= stored})
    return pd.DataFrame(rows), pd.DataFrame(before)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", help="results folders of the iCub experiment")
    args = parser.parse_args(argv)
    runs, before = after_first_module(args.folders)
    groups = runs.groupby(["condition", "first"])
    table = pd.DataFrame({
        "runs": groups.size(),
        "frames in roll after": groups["roll_share"].median(),
        "topple episodes gated": groups["topple_gated"].sum() / groups["topple_episodes"].sum(),
        "roll episodes gated": groups["roll_gated"].sum() / groups["roll_episodes"].sum(),
        "decisions in roll that engage": groups["engage_in_roll"].median(),
        "epsilon": groups["epsilon"].median(),
        "roll DA (unfamiliar)": groups["roll_da"].median(),
        "both learned": groups["both"].sum(),
    })
    with pd.option_context("display.width", 200, "display.max_columns", None, "display.float_format", "{:.3g}".format):
        print(f"after the first stored module ({len(runs)} runs with a module):")
        print(table.to_string())
        print("\nframes in roll before the first storage (median over runs):")
        print(before.pivot(index="folder", columns="condition", values="roll_share_before").to_string())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
