"""Where the noise of the first cycle's learning progress comes from (a study, not a test;
docs/reproduction.md, section 2.8).

    python benchmarks/reward_noise_study.py [--runs 25] [--seed 2026] [--steps 350000] [--set KEY=VALUE ...]

Runs the synthetic experiment's ``curious`` condition (``neurocur/experiments_data/synthetic.toml``,
the experiment's own seeds; ``--seed`` another seed set) with the paper's reward, the default
before section 2.8's third variant (circuit ``cd_misfa``, ``PFC.alpha = 0.2``; ``--set`` may
change them), in this process, and reads the HPC's state at every episode. With
``HPC.reward_error = "episode"`` the dopamine of a
visit is the drop of the episode's mean error since the context's previous visit,
DA = ē(previous visit) − ē(this visit). The error at a state is the distance of the features
from that state's clusters, so each visit's error already compares the features with those
of the state's earlier visits; but the two visits of DA show different windows of the
context's clock. DA is split into two terms, DA = LP_same + W:

- ``LP_same``: the mean, over this visit's frames whose state has a stored error, of (the
  error stored at the frame's state from its previous visit − its error now): how much the
  visit lowered the error *at the states it shows*;
- ``W = DA − LP_same``: the rest, which compares the previous visit's states with this
  visit's states (their errors as stored before this visit), the window term.

Over the first cycle's episodes (before the first module is stored) whose DA and LP_same
are both defined (DA 0 is the VTA's "undefined"), printed: the standard deviation of DA, of
LP_same and of W and the share of DA's variance each explains (their squared correlations
with DA); and, per run, the means after an engage and after a disengage of DA and of
LP_same, tested paired by run (Wilcoxon signed-rank).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from neurocur.analysis import wilcoxon_signed_rank
from neurocur.experiments import load_experiment
from neurocur.experiments.run import run_one
from neurocur.regions.hpc import HPCROC

EXPERIMENT = Path(__file__).resolve().parents[1] / "neurocur" / "experiments_data" / "synthetic.toml"
#: the curious agent's reward before section 2.8's third variant: the paper's learning progress, alpha = 0.2
PAPERS_REWARD = ['circuit="cd_misfa"', "PFC.alpha=0.2"]


def record_same_state_progress(found: list[float]):
    """Wrap ``HPCROC.step`` so that each call appends its episode's LP_same to ``found``; returns
    the original method (put it back when done)."""
    original = HPCROC.step

    def step(self, episode, features, library_features):
        before = self.stored[episode.context, episode.states].copy()  # each state's error at its previous visit
        out = original(self, episode, features, library_features)
        now = np.where(self._known, self._frame_err, np.nan)
        both = ~np.isnan(before) & ~np.isnan(now)
        found.append(float(np.mean(before[both] - now[both])) if both.any() else np.nan)
        return out

    HPCROC.step = step
    return original


def first_cycle(runs: int, seed: int | None, steps: int, sets: list[str]) -> pd.DataFrame:
    """Per first-cycle episode of every run: run, DA, LP_same, W and the previous decision."""
    exp = load_experiment(EXPERIMENT, sets=[*PAPERS_REWARD, *sets], seed=seed)
    condition = exp.conditions["curious"]
    rows = []
    for run in range(runs):
        found: list[float] = []
        original = record_same_state_progress(found)
        try:
            episodes = run_one(condition, run, steps, exp.run_seed(run)).episodes
        finally:
            HPCROC.step = original
        episodes = episodes.assign(lp_same=found, previous=episodes["action"].shift(1))
        stored = episodes.index[episodes["module_learned"]]
        cycle = episodes.loc[: stored[0] - 1] if len(stored) else episodes
        keep = cycle[(cycle["da"] != 0) & cycle["lp_same"].notna() & ~cycle["familiar"]]
        rows.append(keep.assign(w=keep["da"] - keep["lp_same"])[["run", "da", "lp_same", "w", "previous"]])
    return pd.concat(rows, ignore_index=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=25)
    parser.add_argument("--seed", type=int, default=None, help="experiment seed (default: the experiment's own)")
    parser.add_argument("--steps", type=int, default=350_000)
    parser.add_argument("--set", nargs="*", default=[], dest="sets", metavar="KEY=VALUE")
    args = parser.parse_args(argv)
    table = first_cycle(args.runs, args.seed, args.steps, args.sets)
    print(f"{len(table)} first-cycle episodes of {table['run'].nunique()} runs with DA and LP_same defined")
    for term in ("da", "lp_same", "w"):
        r = np.corrcoef(table["da"], table[term])[0, 1]
        print(f"  {term:8s} mean {table[term].mean():+.4f}  sd {table[term].std():.4f}  "
              f"share of DA's variance (r²) {r * r:.2f}")
    means = table.groupby(["run", "previous"])[["da", "lp_same"]].mean().unstack("previous").dropna()
    for term in ("da", "lp_same"):
        engage, disengage = means[(term, "engage")], means[(term, "disengage")]
        test = wilcoxon_signed_rank(engage, disengage)
        spread = table[term].std()
        print(f"  {term:8s} after an engage {engage.mean():+.4f}, after a disengage {disengage.mean():+.4f} "
              f"(means over {len(means)} runs; difference / sd {(engage.mean() - disengage.mean()) / spread:+.3f}); "
              f"{test['test']}: p = {test['p_value']:.2g}")


if __name__ == "__main__":
    main()
