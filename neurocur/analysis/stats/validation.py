"""The neuromodulator models against the canonical results of their source papers: the statistics
(docs/validation.md; the figures are :mod:`neurocur.analysis.figures.validation`).

- ``vigilance`` worlds (``gilzenrat2002``; Gilzenrat, Holmes, Rajkowski, Aston-Jones & Cohen 2002,
  Neural Networks 15:647): :func:`vigilance_per_run` (LC baseline and peak to targets and to
  distractors, the burst/baseline ratio, hits, false alarms, d');
- ``conditioning`` worlds (``schultz1997``; Schultz, Dayan & Montague 1997, Science 275:1593):
  :func:`conditioning_per_run` (the correlation of DA at the cue and at the reward with the
  training trial, the omission dip against baseline);
- ``reward_blocks`` worlds (``adaptive_gain_2005``; Aston-Jones & Cohen 2005, Annu Rev Neurosci
  28:403): :func:`blocks_per_run` (per block of visits: the reward, the LC's tonic drive and
  gain, the share of disengage decisions);
- every canonical task: :func:`over_runs`, the per-run statistics' mean, standard deviation and
  range over runs, condition by condition (``neurocur run`` prints it; ``statistics.csv``);
- a synthetic world with a swap (the NE-plasticity hypothesis run): :func:`relearning_per_run`
  and :func:`relearning_test`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import norm, pearsonr
from statsmodels.stats.multitest import multipletests

from .bootstrap import paired_bootstrap_ci
from .significance import mcnemar_exact, wilcoxon_signed_rank

__all__ = ["d_prime", "over_runs", "over_runs_text", "vigilance_per_run", "conditioning_per_run", "blocks_per_run", "disengaged",
           "relearning_per_run", "relearning_test"]


def d_prime(hits: int, n_targets: int, false_alarms: int, n_distractors: int) -> float:
    """d' = z(hit rate) - z(false-alarm rate), each rate with the log-linear correction
    (k + 0.5) / (n + 1) (Hautus 1995, Behav Res Methods 27:46), so that a rate of 0 or 1 is finite.

    Parameters
    ----------
    hits : int
        Targets responded to.
    n_targets : int
        Targets shown.
    false_alarms : int
        Distractors responded to.
    n_distractors : int
        Distractors shown.

    Returns
    -------
    float
        d', in standard deviations of the noise.
    """
    hit = (hits + 0.5) / (n_targets + 1)
    fa = (false_alarms + 0.5) / (n_distractors + 1)
    return float(norm.ppf(hit) - norm.ppf(fa))


def over_runs(per_run: pd.DataFrame, by: tuple[str, ...] = ("condition",)) -> pd.DataFrame:
    """The per-run table of a canonical task (one row per condition and run, and per ``by`` group
    beyond the condition, e.g. a block) summarised over runs: one row per group and statistic (every
    numeric column but ``run`` and ``by``), with ``runs``, ``mean``, ``sd`` (ddof 1; NaN for one
    run), ``min`` and ``max``; NaN values (a statistic a run could not measure) are left out.

    Parameters
    ----------
    per_run : pandas.DataFrame
        A per-run table with ``run`` and the ``by`` columns.
    by : tuple of str
        The grouping columns, the condition first.

    Returns
    -------
    pandas.DataFrame
        Columns: the ``by`` columns, statistic, runs, mean, sd, min, max; groups in order of
        first appearance.
    """
    by = list(by)
    columns = [c for c in per_run.columns if c not in {"run", *by} and pd.api.types.is_numeric_dtype(per_run[c])]
    rows = []
    for key, group in per_run.groupby(by, sort=False):
        key = key if isinstance(key, tuple) else (key,)
        for column in columns:
            values = group[column].astype(float).dropna()
            rows.append({**dict(zip(by, key)), "statistic": column, "runs": len(values),
                         "mean": float(values.mean()) if len(values) else np.nan,
                         "sd": float(values.std(ddof=1)) if len(values) > 1 else np.nan,
                         "min": float(values.min()) if len(values) else np.nan,
                         "max": float(values.max()) if len(values) else np.nan})
    return pd.DataFrame(rows, columns=[*by, "statistic", "runs", "mean", "sd", "min", "max"])


def over_runs_text(table: pd.DataFrame) -> str:
    """:func:`over_runs`'s table for the terminal: a row per statistic (and group beyond the
    condition), a column per condition, each cell the mean and, over several runs, the range.

    Parameters
    ----------
    table : pandas.DataFrame
        An ``over_runs`` table.

    Returns
    -------
    str
        The text table; ``n/a`` for a statistic no run measured.
    """
    groups = [c for c in table.columns[:table.columns.get_loc("statistic")] if c != "condition"]

    def cell(row) -> str:
        if not np.isfinite(row["mean"]):
            return "n/a"
        return f"{row['mean']:.3g}" + (f" ({row['min']:.3g} to {row['max']:.3g})" if row["runs"] > 1 else "")

    cells = table.assign(cell=table.apply(cell, axis=1))
    wide = cells.pivot_table(index=[*groups, "statistic"], columns="condition", values="cell", aggfunc="first",
                             sort=False)
    return wide[list(dict.fromkeys(table["condition"]))].to_string()


def _runs(episodes: pd.DataFrame):
    return episodes.groupby(["condition", "run"], sort=True)


def vigilance_per_run(episodes: pd.DataFrame) -> pd.DataFrame:
    """Per condition and run of a ``vigilance`` world: LC baseline (mean rate before the stimulus),
    its peak to targets and to distractors, ``burst_ratio`` = mean peak to targets / mean baseline,
    hit and false-alarm rates and d' (:func:`d_prime`).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``vigilance`` world (one row per trial), with ``condition``,
        ``run``, ``target``, ``response``, ``lc_baseline`` and ``lc_peak``.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run): condition, run, trials, targets, baseline, peak_target,
        peak_distractor, burst_ratio (inf for a zero baseline), hit_rate, false_alarm_rate,
        d_prime.
    """
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
    DA at the time of an omitted reward (``omission_dip``; NaN without omissions).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``conditioning`` world (one row per trial), with ``condition``,
        ``run``, ``episode``, ``omitted``, ``da_cue``, ``da_reward`` and ``da_baseline``.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run): condition, run, trials, training_trials, omissions,
        r_cue_trial, r_reward_trial, cue_first, cue_last, reward_first, reward_last, baseline,
        omission_dip.
    """
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


def disengaged(episodes: pd.DataFrame) -> np.ndarray:
    """Whether each episode's decision was a disengage: ``action`` as text (``"disengage"``) or as
    its integer code (1).

    Parameters
    ----------
    episodes : pandas.DataFrame
        Episodes with an ``action`` column.

    Returns
    -------
    numpy.ndarray
        One bool per row of ``episodes``.
    """
    action = episodes["action"]
    return (action.astype(str) == "disengage").to_numpy() if action.dtype.kind not in "iub" else (action == 1).to_numpy()


def blocks_per_run(episodes: pd.DataFrame, block_visits: int) -> pd.DataFrame:
    """Per condition, run and block of ``block_visits`` visits of a ``reward_blocks`` world: the
    mean reward (the utility), ``ne_tonic`` (the LC's tonic drive), ``ne_gain`` and the share of
    disengage decisions, over the block and over its second half (``late_``: after the LC's
    averages have caught up with the block).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``reward_blocks`` world, with ``condition``, ``run``,
        ``episode``, ``action``, ``reward``, ``ne_tonic`` and ``ne_gain``.
    block_visits : int
        Visits (episodes) per block; episode *e* is in block ``e // block_visits``.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run, block): condition, run, block, reward, ne_tonic, ne_gain,
        disengage, late_ne_tonic, late_disengage.
    """
    rows = []
    for (condition, run), ep in _runs(episodes):
        block = ep["episode"].to_numpy() // block_visits
        late = ep["episode"].to_numpy() % block_visits >= block_visits // 2
        away = disengaged(ep)
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


def relearning_per_run(episodes: pd.DataFrame, modules: pd.DataFrame, swap_at: int, source: str) -> pd.DataFrame:
    """Per condition and run of a synthetic world with a swap (a world event at frame ``swap_at``):
    ``relearned`` (a module of ``source``, the swapped-in source, was stored after the swap) and
    ``frames_to_relearn`` = that module's storing frame - ``swap_at``, censored at the frames the
    run had after the swap when none was (the modules' ``source`` is the one shown when stored).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``step`` and ``n_frames`` (in episode
        order within each run).
    modules : pandas.DataFrame
        The modules table, with ``condition``, ``run``, ``source`` and ``step`` (the storing frame).
    swap_at : int
        The frame of the swap.
    source : str
        The swapped-in source.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run): condition, run, relearned, frames_to_relearn.
    """
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
    Holm-adjusted as one family of two.

    Parameters
    ----------
    per_run : pandas.DataFrame
        A ``relearning_per_run`` table.
    a, b : str
        The conditions compared; every run of ``a`` must be a run of ``b``.

    Returns
    -------
    dict
        ``runs``, ``mean_frames_a``, ``mean_frames_b``, ``difference_ci`` (the interval's
        ``(low, high)``), ``relearned_a``, ``relearned_b`` (counts of runs), ``p_frames_holm`` and
        ``p_relearned_holm``.
    """
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
