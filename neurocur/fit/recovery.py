"""Parameter and model recovery (Wilson & Collins 2019, rules 5 and 6): simulate with known truth, fit, compare.

- :func:`parameter_recovery`: data sets simulated at known theta (drawn uniformly within the
  bounds from a seeded generator), each fitted by maximum likelihood on its replay; per
  parameter, Pearson r between true and fitted values, the bias (mean fitted - true), the
  RMSE and the coverage of the profile-likelihood or parametric-bootstrap intervals (:func:`recovery_summary`).
- :func:`model_recovery`: data sets simulated from each of M models (experiment conditions),
  every model fitted to every data set; the confusion matrices count, per generating model,
  which model wins by AIC, by BIC and by the held-out log-likelihood (fitted on the first half
  of the episodes, scored on the second) (:func:`confusion`).

Tables are tidy (one row per data set and parameter, or per data set and fitted model); each
has a figure (:func:`recovery_figure`, :func:`confusion_figure`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from scipy import stats

from ..analysis.figures.style import figure
from ..config import ConfigError
from .bootstrap import parametric_bootstrap
from .compare import score
from .mle import fit_ml
from .study import replay_of, simulate

__all__ = ["confusion", "confusion_figure", "model_recovery", "parameter_recovery", "recovery_figure",
           "recovery_summary", "simulate"]


def parameter_recovery(condition, bounds: Mapping[str, tuple[float, float]], *, n_datasets: int, n_episodes: int,
                       seed: int = 0, starts: int = 3, decision: str = "LC",
                       signal: tuple[str, str] | None = None, progress=None, intervals: str = "profile",
                       bootstrap: int = 200) -> pd.DataFrame:
    """``n_datasets`` fits at known theta, each drawn uniformly within ``bounds``.

    Parameters
    ----------
    condition : Condition
        The experiment condition that simulates and fits the data sets.
    bounds : mapping of str to (float, float)
        The fitted keys and their bounds (the true values are drawn within them).
    n_datasets : int
        The data sets simulated and fitted.
    n_episodes : int
        The episodes of each data set.
    seed : int
        The root of the data sets' seeds and of the true values' draws.
    starts : int
        The local searches of each fit.
    decision : str
        The region whose decisions are the data.
    signal : (str, str), optional
        (region, column): signal replay.
    progress : callable, optional
        ``progress(table so far)``, called after each data set.
    intervals : str
        ``"profile"`` (profile likelihood) or ``"bootstrap"`` (percentile intervals of ``bootstrap``
        replicates, :mod:`.bootstrap`; data set i's replicates are seeded by ``(seed, i)``).
    bootstrap : int
        The bootstrap replicates per data set.

    Returns
    -------
    pandas.DataFrame
        Rows ``dataset, param, true, estimate, ci_low, ci_high, loglik``.
    """
    if intervals not in ("profile", "bootstrap"):
        raise ConfigError("--ci", None, "profile or bootstrap", repr(intervals))
    keys = list(bounds)
    b = np.array([bounds[k] for k in keys], dtype=np.float64)
    root = np.random.SeedSequence(seed)
    draw = np.random.default_rng(root.spawn(1)[0])
    rows = []
    for i, child in enumerate(root.spawn(n_datasets)):
        truth = dict(zip(keys, map(float, draw.uniform(b[:, 0], b[:, 1]))))
        behaviour, _ = simulate(condition, truth, child, n_episodes, decision=decision, signal=signal, name=f"d{i}")
        fit = fit_ml(replay_of(condition, behaviour, child, keys, decision=decision, signal=signal), bounds,
                     starts=starts, seed=i, dataset=f"d{i}", ci=0.95 if intervals == "profile" else None)
        if intervals == "bootstrap":
            fit.ci = parametric_bootstrap(condition, fit.estimate, n_episodes, bounds, replicates=bootstrap,
                                          seed=[seed, i], starts=starts, decision=decision, signal=signal,
                                          dataset=f"d{i}").ci
        for k in keys:
            rows.append({"dataset": f"d{i}", "param": k, "true": truth[k], "estimate": fit.estimate[k],
                         "ci_low": fit.ci[k][0], "ci_high": fit.ci[k][1], "loglik": fit.loglik})
        if progress is not None:
            progress(pd.DataFrame(rows))
    return pd.DataFrame(rows)


def recovery_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per parameter: ``n``, Pearson ``r`` (true, estimate), ``bias`` (mean estimate - true), ``rmse`` and
    ``coverage`` (fraction of intervals holding the truth).

    Parameters
    ----------
    table : pandas.DataFrame
        The rows of :func:`parameter_recovery`.

    Returns
    -------
    pandas.DataFrame
        One row per parameter.
    """
    rows = []
    for param, t in table.groupby("param", sort=False):
        err = t["estimate"] - t["true"]
        r = stats.pearsonr(t["true"], t["estimate"])[0] if len(t) > 2 and t["estimate"].std() > 0 else np.nan
        rows.append({"param": param, "n": len(t), "r": float(r), "bias": float(err.mean()),
                     "rmse": float(np.sqrt((err**2).mean())),
                     "coverage": float(((t["ci_low"] <= t["true"]) & (t["true"] <= t["ci_high"])).mean())})
    return pd.DataFrame(rows)


def recovery_figure(table: pd.DataFrame):
    """Fitted against true value per parameter, with the intervals and the identity line.

    Parameters
    ----------
    table : pandas.DataFrame
        The rows of :func:`parameter_recovery`.

    Returns
    -------
    matplotlib.figure.Figure
        A panel per parameter.
    """
    params = list(dict.fromkeys(table["param"]))
    fig, axes = figure(1, len(params), figsize=(3.8 * len(params), 3.5))
    summary = recovery_summary(table).set_index("param")
    for ax, param in zip(axes[0], params):
        t = table[table["param"] == param]
        ax.errorbar(t["true"], t["estimate"], yerr=[t["estimate"] - t["ci_low"], t["ci_high"] - t["estimate"]],
                    fmt="o", ms=3, lw=0.6, alpha=0.8)
        lo, hi = min(t["true"].min(), t["ci_low"].min()), max(t["true"].max(), t["ci_high"].max())
        ax.plot([lo, hi], [lo, hi], "k--", lw=0.8)
        s = summary.loc[param]
        ax.set(xlabel=f"true {param}", ylabel="fitted", title=f"r = {s['r']:.2f}, bias = {s['bias']:.3g}, "
               f"cover = {s['coverage']:.2f}")
        ax.title.set_fontsize(8)
    return fig


def model_recovery(conditions: Mapping[str, object], bounds: Mapping[str, Mapping[str, tuple[float, float]]], *,
                   n_datasets: int, n_episodes: int, seed: int = 0, starts: int = 2, decision: str = "LC",
                   progress=None) -> pd.DataFrame:
    """Rows ``generating, dataset, fitted, loglik, n_params, n_obs, aic, bic, heldout``
    (:func:`~neurocur.fit.compare.score`): every model (condition, with its ``bounds``, empty for none)
    fitted to ``n_datasets`` data sets simulated from each model (theta drawn uniformly within the
    generating model's bounds). Data set i of every model has the
    same seed (paired).

    Parameters
    ----------
    conditions : mapping of str to Condition
        The models, by name.
    bounds : mapping of str to mapping of str to (float, float)
        Each model's fitted keys and their bounds (empty for none).
    n_datasets : int
        The data sets simulated from each model.
    n_episodes : int
        The episodes of each data set.
    seed : int
        The root of the data sets' seeds and of the true values' draws.
    starts : int
        The local searches of each fit.
    decision : str
        The region whose decisions are the data.
    progress : callable, optional
        ``progress(table so far)``, called after each data set.

    Returns
    -------
    pandas.DataFrame
        Rows ``generating, dataset, fitted, loglik, n_params, n_obs, aic, bic, heldout``.
    """
    root = np.random.SeedSequence(seed)
    children = root.spawn(n_datasets)
    draw = np.random.default_rng(root.spawn(1)[0])
    rows = []
    for i, child in enumerate(children):  # data set by data set, every model's: a partial table stays balanced
        for gen, condition in conditions.items():
            truth = {k: float(draw.uniform(*lohi)) for k, lohi in bounds[gen].items()}
            behaviour, _ = simulate(condition, truth, child, n_episodes, decision=decision, name=f"{gen}/d{i}")
            for name, candidate in conditions.items():
                replay = replay_of(candidate, behaviour, child, list(bounds[name]), decision=decision)
                rows.append({"generating": gen, "dataset": f"{gen}/d{i}", "fitted": name,
                             **score(replay, bounds[name], starts=starts, seed=i)})
            if progress is not None:
                progress(pd.DataFrame(rows))
    return pd.DataFrame(rows)


def confusion(table: pd.DataFrame, by: str) -> pd.DataFrame:
    """P(model wins by ``by`` | generating model): rows generating, columns fitted. ``by`` is ``"aic"`` or
    ``"bic"`` (lowest wins) or ``"heldout"`` (highest wins); a tie shares the win.

    Parameters
    ----------
    table : pandas.DataFrame
        The rows of :func:`model_recovery`.
    by : str
        The score that picks the winner.

    Returns
    -------
    pandas.DataFrame
        Rows generating, columns fitted; each row sums to 1.
    """
    models = list(dict.fromkeys(table["fitted"]))
    out = pd.DataFrame(0.0, index=pd.Index(list(dict.fromkeys(table["generating"])), name="generating"),
                       columns=pd.Index(models, name="fitted"))
    score = table[by] if by == "heldout" else -table[by]
    for (gen, _), rows in table.assign(score=score).groupby(["generating", "dataset"], sort=False):
        best = rows["score"] == rows["score"].max()
        for name in rows.loc[best, "fitted"]:
            out.loc[gen, name] += 1.0 / best.sum()
    return out.div(out.sum(axis=1), axis=0)


def confusion_figure(table: pd.DataFrame, by: Sequence[str] = ("aic", "bic", "heldout")):
    """The confusion matrices side by side (rows: generating model, columns: winning fitted model).

    Parameters
    ----------
    table : pandas.DataFrame
        The rows of :func:`model_recovery`.
    by : sequence of str
        The scores, a panel each (:func:`confusion`).

    Returns
    -------
    matplotlib.figure.Figure
        A panel per score.
    """
    fig, axes = figure(1, len(by), figsize=(3.8 * len(by), 3.5))
    for ax, key in zip(axes[0], by):
        m = confusion(table, key)
        ax.imshow(m.to_numpy(), vmin=0, vmax=1, cmap="Blues")
        for (r, c), v in np.ndenumerate(m.to_numpy()):
            ax.text(c, r, f"{v:.2f}", ha="center", va="center", fontsize=8, color="k" if v < 0.6 else "w")
        ax.set_xticks(range(m.shape[1]), m.columns, rotation=45, ha="right", fontsize=7)
        ax.set_yticks(range(m.shape[0]), m.index, fontsize=7)
        ax.set(title=f"by {key}", xlabel="fitted (winner)", ylabel="generating")
    return fig
