"""How the agent behaves in its learning cycles, and what its reward model held when it decided
(a study of results folders, not a test; docs/reproduction.md, section 2.8).

    neurocur run synthetic --condition curious --seed 2026 --out results/s2026   # and more seed sets
    python benchmarks/first_cycle_study.py results/s2026 results/s2013 results/s7

Pools the runs of the given folders (condition by condition) and prints:

- per cycle (1 = ended by the first stored module; ``neurocur.analysis.cycle_behaviour``), the
  medians over runs of the stored source's epochs, its share of the adaptive module's input,
  the stay that ends the cycle, the frames per change of source and the share of decisions
  that disengaged;
- over each run's first cycle (``neurocur.analysis.stats.reward_model.decision_rewards``, with each
  folder's ``PFC.alpha``), the means over runs of the DA after an engage and after a disengage
  (and a Wilcoxon signed-rank test of the two, paired by run), of the current context's
  R(o, engage) and R(o, disengage) at the decisions, of the share of decisions at which
  R(o, engage) < R(o, disengage), and of the share at which the greedy choice was to leave.
"""

from __future__ import annotations

import argparse

import pandas as pd

from neurocur.analysis import Results, cycle_behaviour, wilcoxon_signed_rank
from neurocur.analysis.stats.reward_model import decision_rewards

CYCLE_COLUMNS = ["source_frames", "source_share", "final_stay", "frames_per_switch", "p_disengage"]
REWARD_COLUMNS = ["da_after_engage", "da_after_disengage", "r_engage", "r_disengage", "engage_below",
                  "greedy_disengage"]


def study(folders: list[str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The cycle table and the first cycle's decision rewards of every run of ``folders``."""
    cycles, rewards = [], []
    for k, folder in enumerate(folders):
        results = Results.load(folder)
        table = cycle_behaviour(results).assign(folder=folder)
        first = results.modules.groupby(["condition", "run"])["episode"].min()
        found = decision_rewards(results, last_episode=first).assign(folder=folder)  # each condition's own alpha
        for t in (table, found):
            t["run"] += 1000 * k  # runs of different folders stay apart when pooled
        cycles.append(table)
        rewards.append(found)
    return pd.concat(cycles, ignore_index=True), pd.concat(rewards, ignore_index=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folders", nargs="+", help="results folders (pooled)")
    parser.add_argument("--cycles", type=int, default=3, help="cycles to print")
    args = parser.parse_args()
    cycles, rewards = study(args.folders)
    pd.set_option("display.width", 200)
    shown = cycles[cycles["cycle"] <= args.cycles]
    table = shown.groupby(["condition", "cycle"])[CYCLE_COLUMNS].median()
    table.insert(0, "runs", shown.groupby(["condition", "cycle"]).size())
    table["source_frames"] /= 1000
    print("Per cycle, medians over runs (source_frames in epochs of 1000 frames):")
    print(table.rename(columns={"source_frames": "source_epochs"}).round(3).to_string(), "\n")
    print("First cycle, means over runs:")
    print(rewards.groupby("condition")[REWARD_COLUMNS].mean().round(4).to_string())
    for condition, part in rewards.groupby("condition"):
        paired = part.dropna(subset=["da_after_engage", "da_after_disengage"])
        if len(paired) > 1:
            test = wilcoxon_signed_rank(paired["da_after_engage"], paired["da_after_disengage"])
            print(f"{condition}: DA after engage vs after disengage, {test['test']}: p = {test['p_value']:.2g}")


if __name__ == "__main__":
    main()
