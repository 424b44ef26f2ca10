"""Hypothesis run 17's checks of Ten et al. 2021's choice models on the study's design (docs/hypotheses.md).

- :func:`parameter_recovery`: a session simulated per participant at the participant's fitted
  coefficients (raw through the participant's own ranges, :func:`~neurocur.fit.ten2021_models.raw_coefficients`),
  refitted hierarchically and by maximum likelihood; the truth on the fitted scale is the raw
  coefficient times the simulated session's span. Pearson r, bias and RMSE per parameter.
- :func:`model_recovery`: sessions simulated from each model, every model fitted hierarchically to each
  simulated group: which model has the lowest iBIC, the protected exceedance probabilities, and the
  confusion matrix of each session's largest Laplace log evidence (Wilson & Collins 2019, eLife 8:e49547).
- :func:`posterior_predictive`: replicates of a group simulated at each participant's fitted coefficients in
  a world following the group's learning curves (:func:`learning_curves`); each activity's share of the free
  choices, the count of participants whose peaks come in the order 1D < I1D < 2D and the change in R's share
  (docs/hypotheses.md entry 16, :mod:`neurocur.analysis.stats.choice_shares`) against people's.

The design is the study's (Ten et al. 2021, Fig. 1): 60 forced trials, then 250 free choices.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from ..analysis.stats.choice_shares import ordered_peaks, peak_bins, share_change
from ..regions.ten2021 import SIGNALS, WINDOW
from .bms import bms
from .ten2021 import ACTIVITIES, FREE_TRIALS
from .ten2021_models import (
    FEATURES,
    KEYS,
    MODELS,
    Session,
    coefficients,
    fit_group,
    model_bounds,
    raw_coefficients,
    session_features,
    simulate_sessions,
)

__all__ = ["P_CORRECT", "choice_statistics", "learning_curves", "model_recovery", "parameter_recovery",
           "posterior_predictive", "true_coefficients"]

#: Each activity's free-play percent correct in the posted data (free group; docs/ten2021.md).
P_CORRECT = (0.90, 0.82, 0.66, 0.50)
#: Participants a play number needs for the learning curve to use it.
MIN_PARTICIPANTS = 20
#: Bins of the free choices (entry 16's 10 bins of 25).
N_BINS = 10
#: The order of the peaks entry 16 counts (1D < I1D < 2D) and the activity whose share change it measures (R).
ORDER, FALLING = (0, 1, 2), ACTIVITIES.index("R")


def true_coefficients(raw: np.ndarray, sessions: Sequence[Session]) -> np.ndarray:
    """The coefficients of the rescaled signals that make the same choices as raw coefficients ``raw`` (S, features)
    on each simulated session: raw times the session's span (0 where the signal is constant).

    Parameters
    ----------
    raw : numpy.ndarray
        (S, len(FEATURES)) raw-signal coefficients, a session each (the repetition's last).
    sessions : sequence of Session
        The S sessions simulated at them (their :attr:`~neurocur.fit.ten2021_models.Session.span`).

    Returns
    -------
    numpy.ndarray
        (S, len(FEATURES)) the coefficients on the fitted (rescaled) scale; the repetition's unchanged.
    """
    out = np.array(raw, dtype=np.float64)
    span = np.array([s.span for s in sessions])
    finite = np.isfinite(span)
    out[:, :len(SIGNALS)] = np.where(finite, out[:, :len(SIGNALS)] * np.where(finite, span, 0.0), 0.0)
    return out


def _simulate(rng, coefs, spans, p_correct, names) -> tuple[list[Session], np.ndarray]:
    """Sessions simulated at fitted coefficients (raw through ``spans``); their Sessions and raw coefficients."""
    raw = raw_coefficients(coefs, spans)
    choices, outcomes, _ = simulate_sessions(rng, raw, p_correct)
    return [session_features(c, o, name=name) for c, o, name in zip(choices, outcomes, names)], raw


def parameter_recovery(sessions: Sequence[Session], maps: pd.DataFrame, model: str, *, seed: int,
                       p_correct=P_CORRECT, **fit) -> pd.DataFrame:
    """Rows ``subject, param, true, hierarchical, ml``: one session simulated per participant of ``sessions`` at
    its MAP under ``model`` (rows ``subject, param, estimate`` of ``maps``), refitted (``fit``: :func:`fit_group`'s
    options).

    Parameters
    ----------
    sessions : sequence of Session
        The participants' sessions: their names and signal spans.
    maps : pandas.DataFrame
        Rows ``subject, param, estimate``: each participant's MAP under ``model``.
    model : str
        The model simulated and refitted (a condition of the experiment ``ten2021``).
    seed : int
        The simulation's and the fits' seed.
    p_correct : array_like
        Each activity's chance of a correct answer (:func:`~neurocur.fit.ten2021_models.simulate_sessions`).
    **fit
        :func:`~neurocur.fit.ten2021_models.fit_group`'s ``starts``, ``n_samples``, ``max_iter`` and ``ml``
        (``ml=False`` skips the per-participant fits and leaves the ``ml`` column empty).

    Returns
    -------
    pandas.DataFrame
        A row per fitted key and participant: the truth on the fitted scale (:func:`true_coefficients`), the
        hierarchical MAP and the maximum-likelihood estimate (NaN with ``ml=False``).
    """
    names = [s.name for s in sessions]
    coefs = coefficients(maps, names)
    simulated, raw = _simulate(np.random.default_rng(seed), coefs, np.array([s.span for s in sessions]),
                               p_correct, names)
    truth = true_coefficients(raw, simulated)
    found = fit_group(simulated, {model: model_bounds([model])[model]}, seed=seed, **fit)
    rows = []
    for key in model_bounds([model])[model]:
        j = FEATURES.index(KEYS[key])
        hier = found["maps"][found["maps"]["param"] == key].set_index("subject")["estimate"]
        ml = found["ml"].set_index("subject")[key] if len(found["ml"]) else pd.Series(np.nan, index=names)
        rows += [{"subject": name, "param": key, "true": truth[i, j], "hierarchical": float(hier[name]),
                  "ml": float(ml[name])} for i, name in enumerate(names)]
    return pd.DataFrame(rows)


def recovery_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per parameter (and group, when ``table`` has one): Pearson r, bias and RMSE of each estimate against the truth."""
    by = [c for c in ("group", "param") if c in table.columns]
    rows = []
    for key, part in table.groupby(by, sort=False):
        key = key if isinstance(key, tuple) else (key,)
        row = dict(zip(by, key))
        for estimate in ("hierarchical", "ml"):
            if part[estimate].notna().all():
                error = part[estimate] - part["true"]
                row |= {f"r_{estimate}": float(np.corrcoef(part["true"], part[estimate])[0, 1]),
                        f"bias_{estimate}": float(error.mean()), f"rmse_{estimate}": float(np.sqrt((error ** 2).mean()))}
        rows.append(row | {"n": len(part)})
    return pd.DataFrame(rows)


def recovery_figure(table: pd.DataFrame):
    """Fitted (hierarchical MAP) against true coefficient, a panel per parameter (rows) and group (columns).

    Parameters
    ----------
    table : DataFrame
        :func:`parameter_recovery`'s rows with a ``group`` column: ``group, param, true, hierarchical``.

    Returns
    -------
    Figure
        The grid of panels, each titled with its group, parameter and Pearson r, the identity line dashed.
    """
    from ..analysis.figures.style import figure

    groups, params = list(dict.fromkeys(table["group"])), list(dict.fromkeys(table["param"]))
    fig, axes = figure(len(params), len(groups), figsize=(3.4 * len(groups), 3.4 * len(params)))
    for (group, param), part in table.groupby(["group", "param"], sort=False):
        ax = axes[params.index(param), groups.index(group)]
        ax.scatter(part["true"], part["hierarchical"], s=6, alpha=0.6)
        low, high = part[["true", "hierarchical"]].min().min(), part[["true", "hierarchical"]].max().max()
        ax.plot([low, high], [low, high], "k--", lw=0.8)
        r = np.corrcoef(part["true"], part["hierarchical"])[0, 1]
        ax.set(title=f"{group} {param}: r = {r:.2f}", xlabel="true", ylabel="fitted (hierarchical)")
        ax.title.set_fontsize(8)
    return fig


def model_recovery(sessions: Sequence[Session], maps: pd.DataFrame, *, seed: int, models: Sequence[str] = MODELS,
                   p_correct=P_CORRECT, **fit) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Sessions simulated from each model at its MAPs (``maps``: rows ``subject, model, param, estimate``), every
    model fitted hierarchically to each simulated group. Returns rows ``generating, fitted, ibic, pxp`` and the
    confusion matrix (rows generating, columns fitted) of each session's largest Laplace log evidence.

    Parameters
    ----------
    sessions : sequence of Session
        The participants' sessions: their names and signal spans.
    maps : pandas.DataFrame
        Rows ``subject, model, param, estimate``: each participant's MAP under each model of ``models``.
    seed : int
        The fits' seed; generating model g's sessions are simulated with ``default_rng([seed, g])``.
    models : sequence of str
        The models, each generating a group and fitted to every group (conditions of the experiment ``ten2021``).
    p_correct : array_like
        Each activity's chance of a correct answer (:func:`~neurocur.fit.ten2021_models.simulate_sessions`).
    **fit
        :func:`~neurocur.fit.ten2021_models.fit_group`'s ``starts``, ``n_samples``, ``max_iter`` (no
        maximum-likelihood fits are made).

    Returns
    -------
    tuple of (pandas.DataFrame, pandas.DataFrame)
        Rows ``generating, fitted, ibic, converged, expected, pxp`` (``expected`` and ``pxp`` from random-effects
        BMS on the Laplace log evidences), and the confusion matrix: the share of each generating group's
        sessions whose Laplace log evidence is largest under each fitted model.
    """
    names = [s.name for s in sessions]
    spans = np.array([s.span for s in sessions])
    bounds = model_bounds(models)
    rows, confusion = [], pd.DataFrame(0.0, index=pd.Index(models, name="generating"),
                                       columns=pd.Index(models, name="fitted"))
    for g, generating in enumerate(models):
        coefs = coefficients(maps[maps["model"] == generating], names)
        simulated, _ = _simulate(np.random.default_rng([seed, g]), coefs, spans, p_correct, names)
        found = fit_group(simulated, bounds, seed=seed, ml=False, **fit)
        selection = bms(found["evidence"]).table(models)
        for h, s in zip(found["hierarchical"].itertuples(), selection.itertuples()):
            rows.append({"generating": generating, "fitted": h.model, "ibic": h.ibic, "converged": h.converged,
                         "expected": s.expected, "pxp": s.pxp})
        winners = np.argmax(found["evidence"], axis=1)
        confusion.loc[generating] = np.bincount(winners, minlength=len(models)) / len(winners)
    return pd.DataFrame(rows), confusion


def learning_curves(sessions: Sequence[tuple[str, np.ndarray, np.ndarray]], *, n_activities: int = 4,
                    minimum: int = MIN_PARTICIPANTS) -> np.ndarray:
    """(activities, plays): the mean outcome of the sessions' n-th trial of each activity (forced and free, in
    order; ``sessions`` as (name, choices, outcomes)), where at least ``minimum`` sessions (all, when there are
    fewer) reached play n; beyond, the last such value.

    Parameters
    ----------
    sessions : sequence of (str, numpy.ndarray, numpy.ndarray)
        Each session's name, choices (activity indices) and 0/1 outcomes, trial by trial.
    n_activities : int
        The activities.
    minimum : int
        The sessions a play number needs for its mean to be used.

    Returns
    -------
    numpy.ndarray
        (activities, plays), plays the longest session's trials: each activity's chance of a correct answer by
        its play number (0-based), as :func:`~neurocur.fit.ten2021_models.simulate_sessions`' ``p_correct``.
    """
    minimum = min(minimum, len(sessions))
    longest = max(len(c) for _, c, _ in sessions)
    total = np.zeros((n_activities, longest))
    count = np.zeros((n_activities, longest))
    for _, choices, outcomes in sessions:
        for k in range(n_activities):
            seen = outcomes[choices == k]
            total[k, :len(seen)] += seen
            count[k, :len(seen)] += 1
    curves = np.zeros_like(total)
    for k in range(n_activities):
        reached = np.flatnonzero(count[k] >= minimum)
        last = reached[-1]
        curves[k, :last + 1] = total[k, :last + 1] / np.maximum(count[k, :last + 1], 1)
        curves[k, last + 1:] = curves[k, last]
    return curves


def free_shares(choices: np.ndarray, *, n_activities: int = 4, n_bins: int = N_BINS) -> np.ndarray:
    """(sessions, bins, activities): each activity's share of each bin of the free choices (``choices`` (sessions,
    free choices), :func:`~neurocur.analysis.stats.choice_shares.share_array`'s bins)."""
    n = choices.shape[1]
    bins = np.arange(n) * n_bins // n
    counts = np.zeros((len(choices), n_bins, n_activities))
    np.add.at(counts, (np.arange(len(choices))[:, None], bins[None, :], choices), 1.0)
    return counts / np.bincount(bins, minlength=n_bins)[None, :, None]


def choice_statistics(shares: np.ndarray) -> dict[str, float]:
    """Entry 16's statistics of a group's shares (participants, bins, activities): each activity's mean share of the
    free choices, the participants whose peaks come in the order 1D < I1D < 2D, the mean change in R's share.

    Parameters
    ----------
    shares : numpy.ndarray
        (participants, bins, activities): each activity's share of each bin of a participant's free choices.

    Returns
    -------
    dict of str to float
        ``share_<activity>`` for each activity, ``ordered_peaks`` and ``change_R``
        (:mod:`neurocur.analysis.stats.choice_shares`).
    """
    out = {f"share_{a}": float(shares[:, :, k].mean()) for k, a in enumerate(ACTIVITIES)}
    out["ordered_peaks"] = float(np.nansum(ordered_peaks(peak_bins(shares), ORDER)))
    out["change_R"] = float(share_change(shares, FALLING).mean())
    return out


def posterior_predictive(sessions: Sequence[Session], raw_sessions, maps: pd.DataFrame, *, seed: int,
                         replicates: int = 200, chunk: int = 20) -> tuple[pd.DataFrame, pd.DataFrame, np.ndarray]:
    """``replicates`` copies of the group (one session per participant at its MAP, rows ``subject, param, estimate``
    of ``maps``), in a world following the group's :func:`learning_curves` (``raw_sessions``: (name, choices,
    outcomes) of the same participants). Returns the rows ``statistic, people, mean, low, high, p`` (the
    replicates' mean and central 95 %; two-sided posterior predictive p), the replicates' statistics, and their
    shares per bin (replicates, bins, activities), averaged over participants.

    Parameters
    ----------
    sessions : sequence of Session
        The participants' sessions: their names and signal spans.
    raw_sessions : sequence of (str, numpy.ndarray, numpy.ndarray)
        The same participants' recorded sessions (name, choices, outcomes), forced and free trials.
    maps : pandas.DataFrame
        Rows ``subject, param, estimate``: each participant's MAP under the model.
    seed : int
        The replicates' seed.
    replicates : int
        Copies of the group simulated.
    chunk : int
        Replicates simulated at once (memory; the draws, and so the replicates, depend on it).

    Returns
    -------
    tuple of (pandas.DataFrame, pandas.DataFrame, numpy.ndarray)
        The rows by statistic, the replicates' statistics (a row each, :func:`choice_statistics`' keys), and
        the replicates' mean shares (replicates, bins, activities).
    """
    names = [s.name for s in sessions]
    coefs = coefficients(maps, names)
    spans = np.array([s.span for s in sessions])
    raw = raw_coefficients(coefs, spans)
    curves = learning_curves(raw_sessions)
    forced = WINDOW * len(ACTIVITIES)
    people = choice_statistics(free_shares(np.array([c[forced:forced + FREE_TRIALS] for _, c, _ in raw_sessions])))
    rng = np.random.default_rng(seed)
    stats, mean_shares = [], []
    for start in range(0, replicates, chunk):
        n = min(chunk, replicates - start)
        choices, _, _ = simulate_sessions(rng, np.tile(raw, (n, 1)), curves)
        shares = free_shares(choices[:, forced:]).reshape(n, len(names), N_BINS, len(ACTIVITIES))
        stats += [choice_statistics(s) for s in shares]
        mean_shares.append(shares.mean(axis=1))
    reps = pd.DataFrame(stats)
    rows = []
    for key, value in people.items():
        r = reps[key].to_numpy()
        p = min(1.0, 2 * min((1 + (r >= value).sum()) / (1 + len(r)), (1 + (r <= value).sum()) / (1 + len(r))))
        rows.append({"statistic": key, "people": value, "mean": float(r.mean()), "low": float(np.quantile(r, 0.025)),
                     "high": float(np.quantile(r, 0.975)), "p": p})
    return pd.DataFrame(rows), reps, np.concatenate(mean_shares)


def ppc_figure(people: Mapping[str, np.ndarray], model: Mapping[str, np.ndarray], titles: Mapping[str, str]):
    """Per group: each activity's share per bin of 25 free choices, people's mean with a 95 % bootstrap interval
    (points) against the replicates' mean and central 95 % (line and band)."""
    from ..analysis.figures.style import figure
    from ..analysis.stats.choice_shares import share_summary

    fig, axes = figure(1, len(people), figsize=(5.0 * len(people), 3.8))
    x = np.arange(1, N_BINS + 1)
    colours = ("tab:blue", "tab:green", "tab:orange", "tab:red")
    for ax, (group, shares) in zip(axes[0], people.items()):
        summary = share_summary(shares, ACTIVITIES)
        for k, (activity, colour) in enumerate(zip(ACTIVITIES, colours)):
            s = summary[summary["option"] == activity]
            ax.errorbar(x, s["mean"], yerr=[s["mean"] - s["ci_low"], s["ci_high"] - s["mean"]], fmt="o", ms=3,
                        color=colour, label=f"{activity} people")
            m = model[group][:, :, k]
            ax.plot(x, m.mean(axis=0), color=colour, lw=1.2)
            ax.fill_between(x, np.quantile(m, 0.025, axis=0), np.quantile(m, 0.975, axis=0), color=colour, alpha=0.2)
        ax.set(title=titles[group], xlabel="bin of 25 free choices", ylabel="share of choices", ylim=(0, 0.6))
        ax.title.set_fontsize(9)
    axes[0, 0].legend(fontsize=7, ncol=2)
    return fig
