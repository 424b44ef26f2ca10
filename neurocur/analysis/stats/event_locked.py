"""Neuromodulators around events: event-locked averages of DA and NE, and tonic against phasic NE.

An event-locked (peri-event) average is the neurophysiologist's view of a neuromodulator:
LC neurons fire phasically to task-relevant events and their tonic rate tracks the
engage/disengage mode (Aston-Jones & Cohen 2005, Annu Rev Neurosci 28:403); dopamine
responds to learning progress (paper section 2.5). Every function takes the tidy episodes
table of :func:`neurocur.analysis.io.load` and returns a tidy DataFrame.

**Events** (:func:`events`), one row each, at an episode of a run:

* ``module_stored``: the episode at which a module was stored (``module_learned``);
* ``context_switch``: the first episode of a visit to another context (the context differs
  from the previous episode's);
* ``familiarity_onset``: a familiar episode after an unfamiliar one (``familiar``; the
  first episode of a run is never an onset).

**Event-locked average** (:func:`event_locked_average`): for each event and each lag ℓ in
−window..window (in episodes of the same run), the signal at episode e + ℓ; lags outside
the run are missing. The per-run mean over the run's events at each lag is one number per
run, and the curve is the mean of the per-run means with a confidence interval across runs
(the percentile bootstrap over runs, Efron & Tibshirani 1993, which stays within the range
of a bounded signal such as NE in [0, 1]; or Student's t). Events close
together share episodes; each is counted on its own. The signals default to ``da`` and every
``ne_*`` column present (``ne_tonic``, ``ne_phasic``, and model-specific ones such as
``ne_gain``).

**Tonic against phasic** (:func:`tonic_phasic`, :func:`tonic_phasic_correlation`): the
adaptive-gain theory predicts that phasic responses are large when tonic NE is moderate and
small when it is high (Aston-Jones & Cohen 2005, their Figure 3).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from neurocur.contract import require_columns

from .bootstrap import BOOTSTRAP_SEED, N_BOOT, bootstrap_ci
from .keys import run_keys

__all__ = ["EVENTS", "events", "event_locked_average", "tonic_phasic", "tonic_phasic_correlation"]

#: Each event kind and the column it is read from.
EVENTS = {"module_stored": "module_learned", "context_switch": "context", "familiarity_onset": "familiar"}

_BASE = ("condition", "run", "episode", "context")


def _sorted(episodes: pd.DataFrame, columns, needed_by: str) -> pd.DataFrame:
    require_columns(episodes, [*_BASE, *columns], needed_by=f"{needed_by} (episodes table)")
    return episodes.sort_values(["condition", "run", "episode"], kind="stable").reset_index(drop=True)


def _kinds(episodes: pd.DataFrame, kinds: str | Sequence[str] | None) -> list[str]:
    if kinds is None:
        return [k for k, column in EVENTS.items() if column in episodes.columns]
    kinds = [kinds] if isinstance(kinds, str) else list(kinds)
    unknown = [k for k in kinds if k not in EVENTS]
    if unknown:
        raise ValueError(f"unknown event kind(s) {unknown}; the kinds are {list(EVENTS)}")
    return kinds


def _event_mask(table: pd.DataFrame, kind: str) -> np.ndarray:
    same_run = (table["condition"] == table["condition"].shift()) & (table["run"] == table["run"].shift())
    if kind == "module_stored":
        return table["module_learned"].astype(bool).to_numpy()
    if kind == "context_switch":
        return (same_run & (table["context"] != table["context"].shift())).to_numpy()
    familiar = table["familiar"].astype(bool)
    return (same_run & familiar & ~familiar.shift(fill_value=False).astype(bool)).to_numpy()


def events(episodes: pd.DataFrame, kinds: str | Sequence[str] | None = None) -> pd.DataFrame:
    """Every event of ``kinds`` (default: every kind of :data:`EVENTS` whose column the table has).

    Columns: condition, run, the swept keys, event, episode, context (of the event's episode).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``episode``, ``context`` and the
        column of each kind (``EVENTS``).
    kinds : str or sequence of str, optional
        Event kinds, keys of ``EVENTS``; None: every kind whose column the table has.

    Returns
    -------
    pandas.DataFrame
        One row per event, the columns above, grouped by kind in ``kinds``' order.

    Raises
    ------
    ValueError
        When a kind is unknown or a column is missing.
    """
    kinds = _kinds(episodes, kinds)
    table = _sorted(episodes, [EVENTS[k] for k in kinds], "events")
    keys = run_keys(table)
    blocks = [table.loc[_event_mask(table, kind), [*keys, "episode", "context"]].assign(event=kind)
              for kind in kinds]
    if not blocks:
        return pd.DataFrame(columns=[*keys, "event", "episode", "context"])
    return pd.concat(blocks, ignore_index=True)[[*keys, "event", "episode", "context"]]


def default_signals(episodes: pd.DataFrame) -> list[str]:
    """``da`` and every ``ne_*`` column of the table, in table order."""
    return [c for c in episodes.columns if c == "da" or (isinstance(c, str) and c.startswith("ne_"))]


def _interval(values: np.ndarray, interval: str, confidence: float, n_boot: int, seed: int) -> tuple[float, float]:
    if interval == "bootstrap":
        return bootstrap_ci(values, n_boot=n_boot, confidence=confidence, seed=seed)
    if len(values) < 2:
        return (math.nan, math.nan)
    half = sps.t.ppf((1 + confidence) / 2, len(values) - 1) * values.std(ddof=1) / math.sqrt(len(values))
    return (values.mean() - half, values.mean() + half)


def event_locked_average(
    episodes: pd.DataFrame,
    signals: str | Sequence[str] | None = None,
    kinds: str | Sequence[str] | None = None,
    window: int = 10,
    *,
    by_context: bool = False,
    interval: str = "bootstrap",
    confidence: float = 0.95,
    n_boot: int = N_BOOT,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """Signals averaged around events, ``window`` episodes either side (see the module docstring).

    ``signals``: columns of the episodes table (default :func:`default_signals`); ``kinds``:
    event kinds (default every kind the table can give); ``by_context``: one curve per context
    of the event's episode; ``interval``: ``"bootstrap"`` (percentile, runs resampled,
    ``n_boot`` from ``seed``) or ``"t"`` (Student's t over the per-run means).

    One row per (condition, [context], event, signal, lag). Columns: condition, the swept keys,
    [context], event, signal, lag (episodes after the event; 0 is the event's episode),
    n_runs (runs with the event and a value at that lag), n_events, mean (of the per-run
    means), ci_low, ci_high (NaN for the t interval with fewer than two runs).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``episode``, ``context``, the
        signals and the column of each kind (``EVENTS``).
    signals : str or sequence of str, optional
        The signals averaged, columns of ``episodes``; None: ``default_signals``.
    kinds : str or sequence of str, optional
        Event kinds, keys of ``EVENTS``; None: every kind whose column the table has.
    window : int
        Lags either side of the event, in episodes; non-negative.
    by_context : bool
        One curve per context of the event's episode (adds a ``context`` column).
    interval : str
        ``"bootstrap"`` or ``"t"``.
    confidence : float
        Coverage of each interval, in (0, 1).
    n_boot : int
        Number of bootstrap resamples of each interval (``interval="bootstrap"``).
    seed : int
        Seed of each bootstrap interval's resamples.

    Returns
    -------
    pandas.DataFrame
        One row per (condition, [context], event, signal, lag), the columns above.

    Raises
    ------
    ValueError
        When ``window`` is negative or not whole, ``interval`` unknown, a kind unknown or a
        column missing.
    """
    if int(window) != window or window < 0:
        raise ValueError(f"event_locked_average: window must be a non-negative number of episodes, got {window!r}")
    if interval not in ("t", "bootstrap"):
        raise ValueError(f"event_locked_average: interval must be 't' or 'bootstrap', got {interval!r}")
    signals = default_signals(episodes) if signals is None else ([signals] if isinstance(signals, str)
                                                                  else list(signals))
    kinds = _kinds(episodes, kinds)
    table = _sorted(episodes, [*signals, *[EVENTS[k] for k in kinds]], "event_locked_average")
    keys = run_keys(table)
    lags = np.arange(-int(window), int(window) + 1)
    values = table[signals].to_numpy(dtype=float)
    per_run = []                                   # (condition, run, context, kind, per-run means (lags, signals), n)
    bounds = table.groupby(["condition", "run"], sort=True).indices
    for kind in kinds:
        mask = _event_mask(table, kind)
        for (condition, run), rows in bounds.items():
            start, stop = rows.min(), rows.max() + 1
            at = np.flatnonzero(mask[start:stop]) + start
            contexts = table["context"].to_numpy()[at] if by_context else np.zeros(len(at), dtype=int)
            for context in np.unique(contexts):
                where = at[contexts == context]
                index = where[:, None] + lags[None, :]
                valid = (index >= start) & (index < stop)
                window_values = np.where(valid[..., None], values[np.clip(index, start, stop - 1)], np.nan)
                finite = np.isfinite(window_values)
                count = finite.sum(axis=0)
                means = np.where(finite, window_values, 0.0).sum(axis=0) / np.where(count > 0, count, 1)
                means[count == 0] = np.nan
                per_run.append((condition, run, context, kind, means, len(where)))
    rows = []
    swept = {c: table.groupby("condition")[c].first() for c in keys[2:]}
    groups: dict = {}
    for condition, _run, context, kind, means, n in per_run:
        groups.setdefault((condition, context, kind), []).append((means, n))
    for (condition, context, kind), items in sorted(groups.items(),
                                                    key=lambda item: (*item[0][:2], kinds.index(item[0][2]))):
        stack = np.stack([m for m, _ in items])                     # (runs, lags, signals)
        n_events = sum(n for _, n in items)
        for j, signal in enumerate(signals):
            for i, lag in enumerate(lags):
                run_means = stack[:, i, j][np.isfinite(stack[:, i, j])]
                low, high = _interval(run_means, interval, confidence, n_boot, seed)
                rows.append({"condition": condition, **{c: swept[c][condition] for c in swept},
                             **({"context": context} if by_context else {}), "event": kind, "signal": signal,
                             "lag": int(lag), "n_runs": len(run_means), "n_events": n_events,
                             "mean": run_means.mean() if len(run_means) else math.nan,
                             "ci_low": low, "ci_high": high})
    columns = ["condition", *keys[2:], *(["context"] if by_context else []), "event", "signal", "lag", "n_runs",
               "n_events", "mean", "ci_low", "ci_high"]
    return pd.DataFrame(rows, columns=columns)


def tonic_phasic(episodes: pd.DataFrame, tonic: str = "ne_tonic", phasic: str = "ne_phasic") -> pd.DataFrame:
    """The phasic-against-tonic scatter table: mean tonic and phasic NE per run and context.

    Columns: condition, run, the swept keys, context, n_episodes, and the two signals' means
    under their own names (``tonic``, ``phasic``).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``episode``, ``context``,
        ``tonic`` and ``phasic``.
    tonic : str
        The column of tonic NE.
    phasic : str
        The column of phasic NE.

    Returns
    -------
    pandas.DataFrame
        One row per (run, context), the columns above.
    """
    table = _sorted(episodes, [tonic, phasic], "tonic_phasic")
    keys = run_keys(table)
    out = table.groupby([*keys, "context"], sort=True).agg(n_episodes=("episode", "size"),
                                                          **{tonic: (tonic, "mean"), phasic: (phasic, "mean")})
    return out.reset_index()


def tonic_phasic_correlation(
    episodes: pd.DataFrame, tonic: str = "ne_tonic", phasic: str = "ne_phasic", *, confidence: float = 0.95
) -> pd.DataFrame:
    """Spearman's ρ between tonic and phasic NE over the episodes of each run, summarised per condition.

    One row per condition. Columns: condition, n_runs (runs where ρ is defined: both signals
    vary), mean_rho (mean of the per-run ρ), ci_low, ci_high (Student's t over the runs),
    rhos (the per-run values, in run order).

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table, with ``condition``, ``run``, ``episode``, ``context``,
        ``tonic`` and ``phasic``.
    tonic : str
        The column of tonic NE.
    phasic : str
        The column of phasic NE.
    confidence : float
        Coverage of the t interval, in (0, 1).

    Returns
    -------
    pandas.DataFrame
        One row per condition, the columns above. A run needs at least three episodes with
        both values for its ρ.
    """
    table = _sorted(episodes, [tonic, phasic], "tonic_phasic_correlation")
    rows = []
    for condition, part in table.groupby("condition", sort=True):
        rhos = []
        for _, run in part.groupby("run", sort=True):
            a, b = run[tonic].to_numpy(dtype=float), run[phasic].to_numpy(dtype=float)
            keep = np.isfinite(a) & np.isfinite(b)
            if keep.sum() > 2 and np.ptp(a[keep]) > 0 and np.ptp(b[keep]) > 0:
                rhos.append(float(sps.spearmanr(a[keep], b[keep]).statistic))
        values = np.array(rhos)
        low, high = _interval(values, "t", confidence, N_BOOT, BOOTSTRAP_SEED)
        rows.append({"condition": condition, "n_runs": len(values),
                     "mean_rho": values.mean() if len(values) else math.nan, "ci_low": low, "ci_high": high,
                     "rhos": rhos})
    return pd.DataFrame(rows)
