"""Model comparison on data: every model fitted to every data set, scored four ways (Wilson & Collins 2019, rule 7).

Per data set and model (:func:`score`): the maximised log-likelihood, AIC and BIC
(:class:`~neurocur.fit.mle.MLFit`), and the split-half held-out log-likelihood (fitted on the
first half of the episodes, scored on the second). Across data sets (:func:`compare_models`,
``loo``): leave-one-data-set-out cross-validation, the model's pooled fit to every other data
set scoring the one left out, which asks whether a model's parameters generalise across
subjects. Random-effects Bayesian model selection (:func:`bms_table`) on the log evidences
-BIC / 2 (Stephan et al. 2009, Rigoux et al. 2014; :mod:`neurocur.fit.bms`) gives each model's
expected frequency, exceedance and protected exceedance probability.

Hierarchically (:func:`compare_hierarchical`, Huys et al. 2011; :mod:`neurocur.fit.hierarchical`):
every model fitted to all data sets at once by empirical-Bayes EM, ranked by its integrated BIC
(sampled, and by Laplace), and random-effects BMS on each data set's Laplace log evidence under the
model's fitted group prior, log p(D_i | mu, sigma) (``bms_table(table, "log_evidence")``).

The tables are tidy, one row per data set and model (:func:`compare_models`, :func:`compare_hierarchical`)
and one per model (:func:`bms_table`, :func:`compare_hierarchical`'s second); :func:`comparison_figure`
draws the first kind.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from ..analysis.figures.style import figure
from .bms import bms
from .hierarchical import MAX_ITER, N_SAMPLES, fit_hierarchical
from .mle import fit_ml
from .study import make_replays

__all__ = ["bms_table", "compare_hierarchical", "compare_models", "comparison_figure", "score", "totals"]


def score(replay, bounds: Mapping[str, tuple[float, float]], *, starts: int, seed: int) -> dict:
    """``loglik, n_params, n_obs, aic, bic, heldout`` of one model on one replayed data set: the fit to
    every episode, and the fit to the first half of the scored episodes scoring the second half.

    Parameters
    ----------
    replay : Replay
        One data set replayed through the model (:class:`~neurocur.fit.replay.Replay`, or anything
        :func:`~neurocur.fit.mle.fit_ml` takes that has ``scored``).
    bounds : mapping of str to (float, float)
        The fitted keys and their bounds (empty: the model has no free parameter and is evaluated).
    starts : int
        Local searches of each fit (:func:`~neurocur.fit.mle.fit_ml`).
    seed : int
        The seed of each fit's design of starts.

    Returns
    -------
    dict
        ``loglik, n_params, n_obs, aic, bic`` of the fit to every episode; ``heldout``: the log-likelihood of
        the passes after the first half of the scored ones, at the fit to that first half.
    """
    full = fit_ml(replay, bounds, starts=starts, seed=seed, ci=None)
    train = np.cumsum(replay.scored) <= replay.n_obs // 2
    first = fit_ml(replay, bounds, starts=starts, seed=seed, ci=None, mask=train)
    return {"loglik": full.loglik, "n_params": full.n_params, "n_obs": full.n_obs, "aic": full.aic,
            "bic": full.bic, "heldout": replay.loglik(first.estimate, ~train)}


def compare_models(experiment, data: Sequence, models: Mapping[str, object],
                   bounds: Mapping[str, Mapping[str, tuple[float, float]]], *, decision: str = "LC",
                   signal: tuple[str, str] | None = None, starts: int = 5, seed: int = 0, loo: bool = True,
                   progress=None) -> pd.DataFrame:
    """Rows ``dataset, model, loglik, n_params, n_obs, aic, bic, heldout, loo``: every model (an experiment
    condition, fitted on its ``bounds``, empty for none) on every data set (Behaviour, replayed with its
    own seed). ``loo``: the data set's log-likelihood under the model's pooled fit to the other data
    sets (NaN with one data set, or ``loo=False``). ``progress(table so far)`` after each model.

    Parameters
    ----------
    experiment : Experiment
        The loaded experiment; its ``run_seed(i)`` seeds the i-th data set without a seed of its own
        (:func:`~neurocur.fit.study.make_replays`).
    data : sequence of Behaviour
        The data sets.
    models : mapping of str to Condition
        The models by name, each an experiment condition (its circuit and world).
    bounds : mapping of str to mapping of str to (float, float)
        Per model, its fitted keys and their bounds (empty for a model without free parameters).
    decision : str
        The region whose decisions are the data.
    signal : (str, str), optional
        (region, column): signal replay, the region replaced by the data set's recorded column.
    starts : int
        Local searches of each fit (:func:`~neurocur.fit.mle.fit_ml`).
    seed : int
        The seed of each fit's design of starts.
    loo : bool
        Score each data set under the pooled fit to the others (one more fit per data set and model).
    progress : callable, optional
        Called with the table so far after each model.

    Returns
    -------
    pandas.DataFrame
        One row per data set and model, in the models' order (:func:`score`'s columns and ``loo``).
    """
    rows = []
    for name, condition in models.items():
        replays = make_replays(experiment, condition, data, list(bounds[name]), decision=decision, signal=signal)
        for k, replay in enumerate(replays):
            left_out = np.nan
            if loo and len(replays) > 1:
                others = [r for j, r in enumerate(replays) if j != k]
                left_out = replay.loglik(fit_ml(others, bounds[name], starts=starts, seed=seed, ci=None).estimate)
            rows.append({"dataset": replay.behaviour.name, "model": name,
                         **score(replay, bounds[name], starts=starts, seed=seed), "loo": left_out})
        if progress is not None:
            progress(pd.DataFrame(rows))
    return pd.DataFrame(rows)


def compare_hierarchical(experiment, data: Sequence, models: Mapping[str, object],
                         bounds: Mapping[str, Mapping[str, tuple[float, float]]], *, decision: str = "LC",
                         signal: tuple[str, str] | None = None, starts: int = 3, seed: int = 0, max_iter: int = MAX_ITER,
                         n_samples: int = N_SAMPLES, progress=None, workers: int = 1
                         ) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Every model fitted hierarchically to all of ``data`` (:func:`~neurocur.fit.hierarchical.fit_hierarchical`,
    each data set a subject replayed with its own seed). Returns rows ``dataset, model, loglik, n_params, n_obs,
    log_evidence`` (the data set's log-likelihood at its MAP, its number of parameters and observations, its
    Laplace log evidence under the model's group prior); rows ``model, ibic, laplace_ibic, log_evidence,
    log_evidence_mcse, log_evidence_laplace, n_params, n_obs, iterations, converged`` (``n_params``: the group's,
    a mu and a sigma per fitted parameter); and the fits by model. ``progress(first table so far)`` after each
    model; ``workers``: processes for each fit's E-steps (the same results for any number).

    Parameters
    ----------
    experiment : Experiment
        The loaded experiment; its ``run_seed(i)`` seeds the i-th data set without a seed of its own
        (:func:`~neurocur.fit.study.make_replays`).
    data : sequence of Behaviour
        The data sets, each a subject.
    models : mapping of str to Condition
        The models by name, each an experiment condition (its circuit and world).
    bounds : mapping of str to mapping of str to (float, float)
        Per model, its fitted keys and their bounds (-inf/inf for none; empty for a model without free
        parameters).
    decision : str
        The region whose decisions are the data.
    signal : (str, str), optional
        (region, column): signal replay, the region replaced by the data set's recorded column.
    starts : int
        Local searches of each subject's first E-step.
    seed : int
        The seed of each fit's Sobol design and evidence samples.
    max_iter : int
        The most E-steps of each fit.
    n_samples : int
        Draws from the group prior for each fit's sampled evidence and iBIC.
    progress : callable, optional
        Called with the first table so far after each model.
    workers : int
        Processes for each fit's E-steps.

    Returns
    -------
    tuple of (pandas.DataFrame, pandas.DataFrame, dict)
        The rows by data set and model, the rows by model, and the
        :class:`~neurocur.fit.hierarchical.HierarchicalFit` of each model by name.
    """
    rows, models_rows, fits = [], [], {}
    for name, condition in models.items():
        replays = make_replays(experiment, condition, data, list(bounds[name]), decision=decision, signal=signal)
        fit = fit_hierarchical(replays, bounds[name], names=[r.behaviour.name for r in replays], seed=seed,
                               starts=starts, max_iter=max_iter, n_samples=n_samples, workers=workers)
        fits[name] = fit
        for replay, evidence in zip(replays, fit.subject_log_evidence):
            estimate = fit.subjects[fit.subjects["dataset"] == replay.behaviour.name]
            rows.append({"dataset": replay.behaviour.name, "model": name,
                         "loglik": replay.loglik(dict(zip(estimate["param"], estimate["estimate"].astype(float)))),
                         "n_params": len(bounds[name]), "n_obs": replay.n_obs, "log_evidence": float(evidence)})
        summary = fit.summary()
        models_rows.append({"model": name, "ibic": fit.ibic, "laplace_ibic": fit.ibic_laplace,
                            **{key: summary[key] for key in ("log_evidence", "log_evidence_mcse",
                                                             "log_evidence_laplace", "n_params", "n_obs",
                                                             "iterations", "converged")}})
        if progress is not None:
            progress(pd.DataFrame(rows))
    return pd.DataFrame(rows), pd.DataFrame(models_rows), fits


def bms_table(table: pd.DataFrame, evidence: str = "bic") -> pd.DataFrame:
    """Per model: ``expected`` frequency, exceedance ``xp``, protected exceedance ``pxp`` and the Bayesian omnibus
    risk ``bor`` (the same on every row), from random-effects BMS on the log evidences: -BIC / 2 by default,
    else the ``evidence`` column itself (a log evidence, e.g. :func:`compare_hierarchical`'s ``log_evidence``).

    Parameters
    ----------
    table : pandas.DataFrame
        One row per data set and model (``dataset``, ``model`` and the ``evidence`` column), as
        :func:`compare_models` or :func:`compare_hierarchical` gives it; every model scored on every data set.
    evidence : str
        The column: ``bic`` (the log evidence is -BIC / 2) or a log evidence itself.

    Returns
    -------
    pandas.DataFrame
        ``model, expected, xp, pxp, bor``, one row per model in the table's order (:func:`~neurocur.fit.bms.bms`).
    """
    wide = table.pivot(index="dataset", columns="model", values=evidence)[list(dict.fromkeys(table["model"]))]
    return bms(-wide.to_numpy() / 2.0 if evidence == "bic" else wide.to_numpy()).table(wide.columns)


def totals(table: pd.DataFrame, selection: pd.DataFrame) -> pd.DataFrame:
    """Per model (in the table's order): its ``loglik, aic, bic, heldout, loo`` summed over the data sets
    (NaN when a score is missing everywhere) and its BMS columns (:func:`bms_table`): what the figure draws
    and ``neurocur compare`` prints.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`compare_models`' rows (``model, loglik, aic, bic, heldout, loo``).
    selection : pandas.DataFrame
        :func:`bms_table`'s rows for the same models.

    Returns
    -------
    pandas.DataFrame
        Indexed by model: the summed scores, then ``expected, xp, pxp, bor``.
    """
    models = list(dict.fromkeys(table["model"]))
    summed = table.groupby("model", sort=False)[["loglik", "aic", "bic", "heldout", "loo"]].sum(min_count=1)
    return summed.reindex(models).join(selection.set_index("model"))


def comparison_figure(table: pd.DataFrame, selection: pd.DataFrame):
    """Three panels: each model's summed BIC above the best model's, its summed held-out and cross-validated
    log-likelihoods below the best's, and its protected exceedance probability.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`compare_models`' rows.
    selection : pandas.DataFrame
        :func:`bms_table`'s rows for the same models.

    Returns
    -------
    matplotlib.figure.Figure
        The figure, on an Agg canvas.
    """
    total = totals(table, selection)
    models = list(total.index)
    fig, axes = figure(1, 3, figsize=(11.4, 3.5))
    axes = axes[0]
    y = np.arange(len(models))
    axes[0].barh(y, total["bic"] - total["bic"].min(), color="0.5")
    axes[0].set(title="summed BIC above the best", xlabel="ΔBIC")
    width = 0.4
    for offset, column, label in ((-width / 2, "heldout", "split-half"), (width / 2, "loo", "leave one data set out")):
        axes[1].barh(y + offset, total[column] - total[column].max(), height=width, label=label)
    axes[1].set(title="held-out log-likelihood below the best", xlabel="Δ log L")
    axes[1].legend(fontsize=7)
    axes[2].barh(y, total["pxp"], color="tab:blue")
    axes[2].set(title=f"random-effects BMS (BOR = {total['bor'].iloc[0]:.2f})", xlabel="protected exceedance",
                xlim=(0, 1))
    for ax in axes:
        ax.set_yticks(y, models, fontsize=7)
        ax.invert_yaxis()
        ax.title.set_fontsize(8)
    return fig
