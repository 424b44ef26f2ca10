"""Yu & Dayan (2005, Neuron 46:681): the statistics of the inferential Posner task with changing cue
identity (``posner`` worlds, ``neurocur run yu_dayan2005``; docs/validation.md, section 4; the figure is
:mod:`neurocur.analysis.figures.posner`).

The episodes carry the probes of ``ach.expected_uncertainty``, ``ne.unexpected_uncertainty`` and
``decision.posner``. A block is the stretch of trials between two changes of the relevant cue (the
world's ``changed`` marker); a block's "late" trials are its second half, when the observer has had
time to settle.

- :func:`posner_by_validity`: per condition, run and validity, over the late trials: ACh beside
  1 - validity, reaction times on valid and invalid trials and the validity effect (invalid - valid),
  accuracy likewise;
- :func:`posner_per_run`: per condition and run: the validity effect over every block's late trials,
  the observer's switches and false switches, the trials it takes to adopt a new relevant cue,
  NE after a change, and performance (accuracy, reaction time, the log score of the cue's prediction of the target).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["with_blocks", "posner_by_validity", "posner_per_run", "trials_to_adopt", "posner_summary"]

#: Trials after a change over which NE and the cue the observer attends are averaged.
AFTER_CHANGE = 20


def with_blocks(episodes: pd.DataFrame) -> pd.DataFrame:
    """``episodes`` sorted by condition, run and trial, with ``block`` (changes so far in the run),
    ``position`` (trials since the block began), ``late`` (in the block's second half, by the
    block's own length) and ``on_cue`` (the attended cue is the relevant one).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``posner`` world, with ``condition``, ``run``, ``episode``,
        ``changed``, ``attended`` and ``relevant``.

    Returns
    -------
    pandas.DataFrame
        A sorted copy with the four columns added.
    """
    ep = episodes.sort_values(["condition", "run", "episode"], kind="stable").reset_index(drop=True)
    runs = [ep["condition"], ep["run"]]
    ep["block"] = ep["changed"].astype(int).groupby(runs).cumsum()
    keys = [ep["condition"], ep["run"], ep["block"]]
    start = ep["episode"].groupby(keys).transform("min")
    length = ep["episode"].groupby(keys).transform("size")
    ep["position"] = ep["episode"] - start
    ep["late"] = ep["position"] >= length // 2
    ep["on_cue"] = ep["attended"] == ep["relevant"]
    return ep


def _validity_effect(ep: pd.DataFrame) -> dict:
    valid = ep["valid"].astype(bool)
    rt_valid, rt_invalid = float(ep.loc[valid, "rt"].mean()), float(ep.loc[~valid, "rt"].mean())
    acc_valid, acc_invalid = float(ep.loc[valid, "correct"].mean()), float(ep.loc[~valid, "correct"].mean())
    return {"rt_valid": rt_valid, "rt_invalid": rt_invalid, "validity_effect": rt_invalid - rt_valid,
            "accuracy_valid": acc_valid, "accuracy_invalid": acc_invalid,
            "accuracy_effect": acc_valid - acc_invalid}


def posner_by_validity(episodes: pd.DataFrame) -> pd.DataFrame:
    """Per condition, run and validity, over the late trials of its blocks: ``ach`` (mean released
    ACh) beside ``expected_ach`` = 1 - validity, ``on_cue`` (share of trials attending the relevant
    cue), and the validity effect in reaction time (``validity_effect`` = mean rt on invalid - on
    valid trials, in samples) and in accuracy (valid - invalid).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``posner`` world (the columns ``with_blocks`` reads, and
        ``validity``, ``valid``, ``ach``, ``rt``, ``correct``).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run, validity), in that order: condition, run, validity, trials,
        ach, expected_ach, on_cue, rt_valid, rt_invalid, validity_effect, accuracy_valid,
        accuracy_invalid, accuracy_effect.
    """
    ep = with_blocks(episodes)
    rows = []
    for (condition, run, validity), g in ep[ep["late"]].groupby(["condition", "run", "validity"], sort=False):
        rows.append({"condition": condition, "run": run, "validity": float(validity), "trials": len(g),
                     "ach": float(g["ach"].mean()), "expected_ach": 1.0 - float(validity),
                     "on_cue": float(g["on_cue"].mean()), **_validity_effect(g)})
    return pd.DataFrame(rows).sort_values(["condition", "run", "validity"], kind="stable").reset_index(drop=True)


def trials_to_adopt(ep: pd.DataFrame) -> np.ndarray:
    """For each change of the relevant cue in one run (``ep`` of :func:`with_blocks`): trials from the
    change until the observer first attends the new relevant cue (0: on the change's own trial),
    censored at the block's length when it never does.

    Parameters
    ----------
    ep : pandas.DataFrame
        One run's trials, as ``with_blocks`` returns them.

    Returns
    -------
    numpy.ndarray
        One value per change, in order (float).
    """
    out = []
    for _, block in ep[ep["block"] > 0].groupby("block", sort=True):
        hit = np.flatnonzero(block["on_cue"].to_numpy())
        out.append(hit[0] if len(hit) else len(block))
    return np.asarray(out, dtype=float)


def posner_per_run(episodes: pd.DataFrame) -> pd.DataFrame:
    """Per condition and run: ``validity_effect`` (rt invalid - valid over every block's late trials,
    samples), ``switches`` (the observer re-initialised, Y6) and ``false_switches`` (it did while
    attending the relevant cue), per 1000 trials; ``trials_to_adopt`` (mean over the run's changes,
    :func:`trials_to_adopt`); ``ne_after_change`` and ``ne_settled`` (mean NE over the
    ``AFTER_CHANGE`` trials after a change, and over the late trials); ``on_cue`` (share of every
    trial attending the relevant cue); ``accuracy``, ``rt`` (mean samples) and ``prediction_score``
    (the mean log2 of the prior probability the cue gave the target's actual side: a proper score
    of the observer's prediction of the target, 0 at best, -1 for a coin, lower when overconfident).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of a ``posner`` world (the columns ``with_blocks`` reads, and
        ``valid``, ``rt``, ``correct``, ``switched``, ``ne``, ``prior``).

    Returns
    -------
    pandas.DataFrame
        One row per (condition, run): condition, run, trials, changes, then the columns above.
    """
    ep = with_blocks(episodes)
    rows = []
    for (condition, run), g in ep.groupby(["condition", "run"], sort=False):
        after = (g["block"] > 0) & (g["position"] < AFTER_CHANGE)
        on_cue, switched = g["on_cue"].to_numpy(), g["switched"].astype(bool).to_numpy()
        rows.append({
            "condition": condition, "run": run, "trials": len(g), "changes": int(g["changed"].sum()),
            "validity_effect": _validity_effect(g[g["late"]])["validity_effect"],
            "switches": 1000.0 * switched.sum() / len(g),
            "false_switches": 1000.0 * (switched & on_cue).sum() / len(g),
            "trials_to_adopt": float(trials_to_adopt(g).mean()) if g["changed"].any() else np.nan,
            "ne_after_change": float(g.loc[after, "ne"].mean()) if after.any() else np.nan,
            "ne_settled": float(g.loc[g["late"], "ne"].mean()),
            "on_cue": float(on_cue.mean()), "accuracy": float(g["correct"].mean()),
            "rt": float(g["rt"].mean()), "prediction_score": float(np.log2(g["prior"]).mean()),
        })
    return pd.DataFrame(rows)


def posner_summary(per_run: pd.DataFrame) -> pd.DataFrame:
    """Per condition (in the table's order): the mean over runs of every column of :func:`posner_per_run`.

    Parameters
    ----------
    per_run : pandas.DataFrame
        A ``posner_per_run`` table.

    Returns
    -------
    pandas.DataFrame
        Indexed by condition; one column per averaged column (all but condition, run, trials
        and changes).
    """
    columns = [c for c in per_run.columns if c not in ("condition", "run", "trials", "changes")]
    return per_run.groupby("condition", sort=False)[columns].mean()
