"""The PFC's reward model (eq 14) replayed from a run's recorded DA and decisions, and what it held
when the agent decided (docs/reproduction.md, section 2.8).

The PFC updates ``R[o, a, o']`` (previous context, previous decision, context) with each
episode's DA (:class:`neurocur.regions.pfc.PFCLSPI`); the episodes table records the context,
the DA and the decision of every episode, so the model can be rebuilt exactly, with the same
updates in the same order (:func:`replay_reward_model`). :func:`decision_rewards` then asks, per
run and over a chosen span of episodes, whether the estimates the agent decided on were the
rewards it had been paid: the mean DA after an engage and after a disengage, against the mean
of ``R(o, engage)`` and ``R(o, disengage)`` for the current context at each decision.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from neurocur.analysis.results import Results
from neurocur.contract import require_columns
from neurocur.regions.pfc import ACTIONS, DISENGAGE, ENGAGE, PFCLSPI, RewardModel

__all__ = ["replay_reward_model", "decision_rewards"]


def replay_reward_model(run: pd.DataFrame, n_contexts: int, alpha: float | str) -> np.ndarray:
    """(n_episodes, n_contexts, 2): ``R(o, a)`` = sum over o' of P[o, a, o'] R[o, a, o'] after each
    episode of one run (episode order, from its first), as the PFC computes it before deciding.

    ``alpha``: the run's ``PFC.alpha`` (a rate, or ``"sample_average"``). The first episode
    updates nothing (the PFC has no previous context yet).

    Parameters
    ----------
    run : pandas.DataFrame
        One run's episodes in episode order, with ``context``, ``da`` and ``action``
        (``"engage"`` or ``"disengage"``).
    n_contexts : int
        The world's number of contexts (the model's size).
    alpha : float or str
        Eq 14's rate, or ``"sample_average"``.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_episodes, n_contexts, 2)``; the last axis is (engage, disengage).

    Raises
    ------
    ValueError
        When a column is missing.
    """
    require_columns(run, ["context", "da", "action"], needed_by="replay_reward_model")
    model = RewardModel(n_contexts, alpha)
    out = np.empty((len(run), n_contexts, 2))
    previous = None
    for t, (context, da, action) in enumerate(zip(run["context"].to_numpy(), run["da"].to_numpy(dtype=float),
                                                  run["action"].to_numpy())):
        if previous is not None:
            model.update(*previous, context, da)
        out[t] = model.expected()
        previous = (context, ACTIONS.index(action))
    return out


def decision_rewards(results: Results, alphas=None, *, last_episode=None) -> pd.DataFrame:
    """Per run: the rewards after each kind of decision against the estimates decided on.

    ``alphas``: eq 14's rate per condition (``{condition: alpha}``), or one for all; by default
    each condition's value estimator's own (the ``alpha`` of its :class:`~neurocur.regions.pfc.PFCLSPI`
    region, :meth:`~neurocur.analysis.results.Results.region_param`). Each condition's number of
    contexts sizes the model (eqs 12-13 spread a disengage over all the other contexts, visited or not). ``last_episode``: a Series
    indexed by (condition, run) of the last episode to include (e.g. the first module's storing
    episode, for the first cycle); runs without one are left out; None takes every episode.

    Columns: condition, run, n_decisions, da_after_engage, da_after_disengage (the mean DA of
    the episodes each kind of decision led to), r_engage, r_disengage (the mean of the current
    context's R(o, engage) and R(o, disengage) at the decisions), engage_below (the share of
    decisions at which R(o, engage) < R(o, disengage)) and greedy_disengage (the share at which
    the recorded Q_disengage > Q_engage).

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables; its episodes need ``condition``, ``run``, ``episode``,
        ``context``, ``da``, ``action``, ``q_engage`` and ``q_disengage``.
    alphas : dict of str to float or str, or float or str, optional
        Eq 14's rate per condition, or one for all; None: each condition's own.
    last_episode : pandas.Series, optional
        The last episode of each run included, indexed by (condition, run); None: every episode.

    Returns
    -------
    pandas.DataFrame
        One row per run included, the columns above.

    Raises
    ------
    ValueError
        When a column is missing.
    """
    episodes = results.episodes
    alphas = results.region_param(PFCLSPI, "alpha") if alphas is None else alphas
    require_columns(episodes, ["condition", "run", "episode", "context", "da", "action", "q_engage", "q_disengage"],
                    needed_by="decision_rewards")
    rows = []
    for (condition, run), table in episodes.sort_values(["condition", "run", "episode"]).groupby(["condition", "run"]):
        alpha = alphas[condition] if isinstance(alphas, dict) else alphas
        estimates = replay_reward_model(table, len(results.spec_of(condition).context_names), alpha)
        keep = np.ones(len(table), dtype=bool)
        if last_episode is not None:
            if (condition, run) not in last_episode.index:
                continue
            keep = table["episode"].to_numpy() <= last_episode[(condition, run)]
        contexts = table["context"].to_numpy()
        at = estimates[np.arange(len(table)), contexts]  # (n, 2): the current context's R(o, .)
        led_by = table["action"].shift().to_numpy()  # the decision each episode followed
        da = table["da"].to_numpy(dtype=float)
        rows.append({
            "condition": condition, "run": run, "n_decisions": int(keep.sum()),
            "da_after_engage": _mean(da[keep & (led_by == "engage")]),
            "da_after_disengage": _mean(da[keep & (led_by == "disengage")]),
            "r_engage": _mean(at[keep, ENGAGE]), "r_disengage": _mean(at[keep, DISENGAGE]),
            "engage_below": float(np.mean(at[keep, ENGAGE] < at[keep, DISENGAGE])),
            "greedy_disengage": float(np.mean((table["q_disengage"] > table["q_engage"]).to_numpy()[keep])),
        })
    return pd.DataFrame(rows)


def _mean(values: np.ndarray) -> float:
    return float(values.mean()) if len(values) else float("nan")
