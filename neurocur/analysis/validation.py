"""The neuromodulator models against the canonical results of their source papers (docs/validation.md).

Three tasks, each a world type with its shipped experiment, its statistics and its figure:

- ``vigilance`` (``gilzenrat2002``; Gilzenrat, Holmes, Rajkowski, Aston-Jones & Cohen 2002,
  Neural Networks 15:647): :func:`vigilance_per_run` (LC baseline and peak to targets and to
  distractors, the burst/baseline ratio, hits, false alarms, d') and :func:`fig_vigilance`;
- ``conditioning`` (``schultz1997``; Schultz, Dayan & Montague 1997, Science 275:1593):
  :func:`conditioning_per_run` (the correlation of DA at the cue and at the reward with the
  training trial, the omission dip against baseline) and :func:`fig_conditioning`;
- ``reward_blocks`` (``adaptive_gain_2005``; Aston-Jones & Cohen 2005, Annu Rev Neurosci
  28:403): :func:`blocks_per_run` (per block of visits: the reward, the LC's tonic drive and
  gain, the share of disengage decisions) and :func:`fig_blocks`.

:func:`write_validation` writes a results folder's table (``validation.csv``) and figure
(``figures/validation.png``) by the folder's world type, and nothing for another world.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import norm, pearsonr
from statsmodels.stats.multitest import multipletests

from neurocur.results import ResultsStore

from .bootstrap import paired_bootstrap_ci
from .significance import mcnemar_exact, wilcoxon_signed_rank
from .style import figure, save_figures, style

__all__ = ["WORLD_TYPES", "d_prime", "vigilance_per_run", "conditioning_per_run", "blocks_per_run",
           "fig_vigilance", "fig_conditioning", "fig_blocks", "write_validation", "relearning_per_run",
           "relearning_test", "fig_relearning"]


def d_prime(hits: int, n_targets: int, false_alarms: int, n_distractors: int) -> float:
    """d' = z(hit rate) - z(false-alarm rate), each rate with the log-linear correction
    (k + 0.5) / (n + 1) (Hautus 1995, Behav Res Methods 27:46), so that a rate of 0 or 1 is finite."""
    hit = (hits + 0.5) / (n_targets + 1)
    fa = (false_alarms + 0.5) / (n_distractors + 1)
    return float(norm.ppf(hit) - norm.ppf(fa))


def _runs(episodes: pd.DataFrame):
    return episodes.groupby(["condition", "run"], sort=True)


def vigilance_per_run(episodes: pd.DataFrame) -> pd.DataFrame:
    """Per condition and run of a ``vigilance`` world: LC baseline (mean rate before the stimulus),
    its peak to targets and to distractors, ``burst_ratio`` = mean peak to targets / mean baseline,
    hit and false-alarm rates and d' (:func:`d_prime`)."""
    rows = []
    for (condition, run), ep in _runs(episodes):
        target, response = ep["target"].astype(bool).to_numpy(), ep["response"].astype(bool).to_numpy()
        n_t, n_d = int(target.sum()), int((~target).sum())
        baseline = float(ep["lc_baseline"].mean())
        rows.append({
            "condition": condition, "run": run, "trials": len(ep), "targets": n_t,
            "baseline": baseline, "peak_target": float(ep["lc_peak"][target].mean()),
            "peak_distractor": float(ep["lc_peak"][~target].mean()),
            "burst_ratio": float(ep["lc_peak"][target].mean()) / baseline if baseline > 0 else np.inf,
            "hit_rate": float(response[target].mean()), "false_alarm_rate": float(response[~target].mean()),
            "d_prime": d_prime(int(response[target].sum()), n_t, int(response[~target].sum()), n_d),
        })
    return pd.DataFrame(rows)


def conditioning_per_run(episodes: pd.DataFrame) -> pd.DataFrame:
    """Per condition and run of a ``conditioning`` world, over the training trials (those before
    the run's first omitted reward; every trial without one): Pearson's r of DA at the cue and
    of DA at the reward with the trial index, and DA at the cue and at the reward on the first
    and the last of them; over every trial, the baseline (mean DA before the cue) and the mean
    DA at the time of an omitted reward (``omission_dip``; NaN without omissions)."""
    rows = []
    for (condition, run), ep in _runs(episodes):
        omitted = ep[ep["omitted"].astype(bool)]
        training = ep[ep["episode"] < omitted["episode"].min()] if len(omitted) else ep
        trial = training["episode"].to_numpy(dtype=float)
        rows.append({
            "condition": condition, "run": run, "trials": len(ep), "training_trials": len(training),
            "omissions": len(omitted),
            "r_cue_trial": float(pearsonr(trial, training["da_cue"]).statistic),
            "r_reward_trial": float(pearsonr(trial, training["da_reward"]).statistic),
            "cue_first": float(training["da_cue"].iloc[0]), "cue_last": float(training["da_cue"].iloc[-1]),
            "reward_first": float(training["da_reward"].iloc[0]), "reward_last": float(training["da_reward"].iloc[-1]),
            "baseline": float(ep["da_baseline"].mean()),
            "omission_dip": float(omitted["da_reward"].mean()) if len(omitted) else np.nan,
        })
    return pd.DataFrame(rows)


def _disengaged(episodes: pd.DataFrame) -> np.ndarray:
    action = episodes["action"]
    return (action.astype(str) == "disengage").to_numpy() if action.dtype.kind not in "iub" else (action == 1).to_numpy()


def blocks_per_run(episodes: pd.DataFrame, block_visits: int) -> pd.DataFrame:
    """Per condition, run and block of ``block_visits`` visits of a ``reward_blocks`` world: the
    mean reward (the utility), ``ne_tonic`` (the LC's tonic drive), ``ne_gain`` and the share of
    disengage decisions, over the block and over its second half (``late_``: after the LC's
    averages have caught up with the block)."""
    rows = []
    for (condition, run), ep in _runs(episodes):
        block = ep["episode"].to_numpy() // block_visits
        late = ep["episode"].to_numpy() % block_visits >= block_visits // 2
        away = _disengaged(ep)
        for k in np.unique(block):
            m = block == k
            rows.append({
                "condition": condition, "run": run, "block": int(k),
                "reward": float(ep["reward"][m].mean()), "ne_tonic": float(ep["ne_tonic"][m].mean()),
                "ne_gain": float(ep["ne_gain"][m].mean()), "disengage": float(away[m].mean()),
                "late_ne_tonic": float(ep["ne_tonic"][m & late].mean()),
                "late_disengage": float(away[m & late].mean()),
            })
    return pd.DataFrame(rows)


def fig_vigilance(episodes: pd.DataFrame, per_run: pd.DataFrame):
    """Left: the LC's baseline and its peak to targets and to distractors, per mode (bars, mean over
    runs; dots, runs). Right: hit rate, false-alarm rate and d' per mode."""
    with style():
        fig, axes = figure(1, 2, figsize=(9.0, 3.6))
        conditions = list(dict.fromkeys(per_run["condition"]))
        x = np.arange(len(conditions))
        for i, (column, label) in enumerate((("baseline", "baseline"), ("peak_target", "peak, targets"),
                                             ("peak_distractor", "peak, distractors"))):
            means = [per_run.loc[per_run["condition"] == c, column].mean() for c in conditions]
            axes[0, 0].bar(x + (i - 1) * 0.27, means, width=0.27, label=label)
        axes[0, 0].set_xticks(x, conditions)
        axes[0, 0].set_ylabel("LC firing rate, clip(v, 0, 1)")
        axes[0, 0].set_title("LC response (Gilzenrat et al. 2002)")
        axes[0, 0].legend(fontsize=8)
        ax = axes[0, 1]
        for i, (column, label) in enumerate((("hit_rate", "hits"), ("false_alarm_rate", "false alarms"))):
            means = [per_run.loc[per_run["condition"] == c, column].mean() for c in conditions]
            ax.bar(x + (i - 0.5) * 0.35, means, width=0.35, label=label)
        ax.set_xticks(x, conditions)
        ax.set_ylabel("rate")
        twin = ax.twinx()
        twin.plot(x, [per_run.loc[per_run["condition"] == c, "d_prime"].mean() for c in conditions], "ko-", label="d'")
        twin.set_ylabel("d'")
        twin.grid(False)
        ax.set_title("performance")
        ax.legend(fontsize=8, loc="upper left")
        twin.legend(fontsize=8, loc="upper right")
    return fig


def fig_conditioning(episodes: pd.DataFrame):
    """DA at the cue and at the reward's time over training trials (mean over runs; omitted trials
    marked), the baseline, and the omission dip (Schultz et al. 1997, Fig. 1)."""
    with style():
        fig, axes = figure(1, 2, figsize=(9.0, 3.6), gridspec_kw={"width_ratios": [2, 1]})
        ax = axes[0, 0]
        rewarded = episodes[~episodes["omitted"].astype(bool)]
        for column, label in (("da_cue", "DA at the cue"), ("da_reward", "DA at the reward")):
            mean = rewarded.groupby("episode")[column].mean()
            ax.plot(mean.index, mean.to_numpy(), label=label)
        omitted = episodes[episodes["omitted"].astype(bool)]
        if len(omitted):
            ax.plot(omitted["episode"], omitted["da_reward"], "v", ms=3, color="C3", label="reward omitted")
        ax.axhline(float(episodes["da_baseline"].mean()), color="0.5", lw=0.8, ls="--", label="baseline")
        ax.set_xlabel("trial")
        ax.set_ylabel("DA = TD error (reward units)")
        ax.set_title("DA moves from the reward to the cue")
        ax.legend(fontsize=8)
        ax = axes[0, 1]
        late = episodes[episodes["episode"] >= episodes["episode"].max() * 0.6]
        groups = {"early, rewarded": episodes[(episodes["episode"] < 10) & ~episodes["omitted"].astype(bool)],
                  "late, rewarded": late[~late["omitted"].astype(bool)], "late, omitted": late[late["omitted"].astype(bool)]}
        x = np.arange(len(groups))
        for i, (column, label) in enumerate((("da_cue", "cue"), ("da_reward", "reward time"))):
            ax.bar(x + (i - 0.5) * 0.35, [g[column].mean() if len(g) else np.nan for g in groups.values()],
                   width=0.35, label=label)
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xticks(x, list(groups), rotation=20, fontsize=8)
        ax.set_title("the three panels of their Fig. 1")
        ax.legend(fontsize=8)
    return fig


def fig_blocks(episodes: pd.DataFrame, block_visits: int):
    """Per condition (rows): the reward, the LC's tonic drive and the share of disengage decisions
    over visits (moving averages of ``block_visits // 25`` visits, mean over runs), blocks marked."""
    conditions = list(dict.fromkeys(episodes["condition"]))
    width = max(1, block_visits // 25)
    with style():
        fig, axes = figure(len(conditions), 1, figsize=(8.0, 2.6 * len(conditions)), sharex=True)
        for row, condition in enumerate(conditions):
            ep = episodes[episodes["condition"] == condition].copy()
            ep["disengaged"] = _disengaged(ep).astype(float)
            mean = ep.groupby("episode")[["reward", "ne_tonic", "disengaged"]].mean()
            smooth = mean.rolling(width, min_periods=1).mean()
            ax = axes[row, 0]
            for column, label in (("reward", "utility (reward)"), ("ne_tonic", "LC tonic drive (1 - engagement)"),
                                  ("disengaged", "P(disengage)")):
                ax.plot(smooth.index, smooth[column].to_numpy(), label=label)
            for k in range(1, int(mean.index.max()) // block_visits + 1):
                ax.axvline(k * block_visits, color="0.5", lw=0.8, ls="--")
            ax.set_title(condition)
            ax.set_ylim(-0.05, 1.05)
            ax.legend(fontsize=8, loc="center right")
        axes[-1, 0].set_xlabel("visit")
    return fig


def relearning_per_run(episodes: pd.DataFrame, modules: pd.DataFrame, swap_at: int, source: str) -> pd.DataFrame:
    """Per condition and run of a synthetic world with a swap (a world event at frame ``swap_at``):
    ``relearned`` (a module of ``source``, the swapped-in source, was stored after the swap) and
    ``frames_to_relearn`` = that module's storing frame - ``swap_at``, censored at the frames the
    run had after the swap when none was (the modules' ``source`` is the one shown when stored)."""
    rows = []
    for (condition, run), ep in _runs(episodes):
        end = int(ep["step"].iloc[-1] + ep["n_frames"].iloc[-1])
        mine = modules[(modules["condition"] == condition) & (modules["run"] == run)
                       & (modules["source"] == source) & (modules["step"] >= swap_at)]
        first = int(mine["step"].min()) if len(mine) else None
        rows.append({"condition": condition, "run": run, "relearned": first is not None,
                     "frames_to_relearn": (first if first is not None else end) - swap_at})
    return pd.DataFrame(rows)


def relearning_test(per_run: pd.DataFrame, a: str, b: str) -> dict:
    """Condition ``a`` against ``b``, paired by run: the mean censored frames to re-learn with the
    bootstrap 95% interval of the paired difference a - b (:func:`~.bootstrap.paired_bootstrap_ci`),
    the Wilcoxon signed-rank p of that difference and McNemar's exact p of ``relearned``, both
    Holm-adjusted as one family of two."""
    x = per_run[per_run["condition"] == a].set_index("run")
    y = per_run[per_run["condition"] == b].set_index("run").loc[x.index]
    frames = wilcoxon_signed_rank(x["frames_to_relearn"], y["frames_to_relearn"])
    learned = mcnemar_exact(x["relearned"], y["relearned"])
    holm = multipletests([frames["p_value"], learned["p_value"]], method="holm")[1]
    ci = paired_bootstrap_ci(x["frames_to_relearn"], y["frames_to_relearn"])["difference"]
    return {"runs": len(x), "mean_frames_a": float(x["frames_to_relearn"].mean()),
            "mean_frames_b": float(y["frames_to_relearn"].mean()),
            "difference_ci": ci, "relearned_a": int(x["relearned"].sum()), "relearned_b": int(y["relearned"].sum()),
            "p_frames_holm": float(holm[0]), "p_relearned_holm": float(holm[1])}


def fig_relearning(per_run: pd.DataFrame, a: str, b: str):
    """Frames from the swap to the first module of the swapped-in source, per run, ``b`` and ``a``
    side by side (a line joins the two runs of a seed; hollow markers: censored, not re-learned)."""
    with style():
        fig, axes = figure(1, 1, figsize=(4.5, 3.8))
        ax = axes[0, 0]
        x = per_run[per_run["condition"] == b].set_index("run")
        y = per_run[per_run["condition"] == a].set_index("run").loc[x.index]
        for run in x.index:
            ax.plot([0, 1], [x.loc[run, "frames_to_relearn"] / 1e3, y.loc[run, "frames_to_relearn"] / 1e3],
                    color="0.6", lw=0.8)
        for i, t in enumerate((x, y)):
            done = t["relearned"].astype(bool)
            ax.plot(np.full(done.sum(), i), t["frames_to_relearn"][done] / 1e3, "o", color=f"C{i}")
            ax.plot(np.full((~done).sum(), i), t["frames_to_relearn"][~done] / 1e3, "o", mfc="none", color=f"C{i}")
        ax.set_xticks([0, 1], [b, a])
        ax.set_xlim(-0.4, 1.4)
        ax.set_ylabel("frames from the swap to re-learning (thousands)")
        ax.set_title("re-learning after the world changes")
    return fig


def _world_table(results_dir) -> dict:
    config = ResultsStore(results_dir).config() or {}
    worlds = [c.get("world", {}) for c in config.get("conditions", {}).values()]
    return worlds[0] if worlds else {}


#: The world types this module reads (a results folder of another world gets nothing).
WORLD_TYPES = ("vigilance", "conditioning", "reward_blocks")


def write_validation(results_dir: str | Path, *, dpi: int = 120) -> list[Path]:
    """For a results folder of a :data:`WORLD_TYPES` world: ``validation.csv`` (the per-run
    statistics) and ``figures/validation.png``; returns the paths (none for another world)."""
    world = _world_table(results_dir)
    kind = world.get("type", "synthetic")
    if kind not in WORLD_TYPES:
        return []
    episodes, _ = ResultsStore(results_dir).load()
    if kind == "vigilance":
        table = vigilance_per_run(episodes)
        fig = fig_vigilance(episodes, table)
    elif kind == "conditioning":
        table = conditioning_per_run(episodes)
        fig = fig_conditioning(episodes)
    else:
        block_visits = int(world.get("block_visits", 500))
        table = blocks_per_run(episodes, block_visits)
        fig = fig_blocks(episodes, block_visits)
    out = Path(results_dir)
    (out / "figures").mkdir(exist_ok=True)
    table.to_csv(out / "validation.csv", index=False)
    return [out / "validation.csv", *save_figures({"validation": fig}, out / "figures", dpi)]
