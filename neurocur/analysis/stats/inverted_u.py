"""Is performance an inverted U of a level (tonic NE, gain, learnability)? The two-lines test.

A quadratic fit is not a test of an inverted U: a monotone curve that flattens, or one with a
plateau, gives a significant negative x² term (Simonsohn 2018). The test here is Simonsohn's
**two-lines test** (Simonsohn 2018, *Advances in Methods and Practices in Psychological
Science* 1:538–555), with his "Robin Hood" break point:

1. **Flexible fit.** With a few levels and several runs per level (a sweep), the most
   flexible fit is the level means ŷ_l, each with its standard error sqrt(MSE / n_l) (MSE:
   the pooled within-level variance; Simonsohn fits a GAM, which with few distinct x is
   this). The *flat region* is, among the levels strictly inside the 10th–90th percentiles
   of x (so the break is never at an extreme), those with ŷ_l + SE_l ≥ the highest ŷ there.
2. **Two interrupted regressions** at a break x_c:
   y = b0 + b1·x_low + b2·x_high + b3·high (+ one intercept per run, ``paired``), with
   x_low = x − x_c below the break (else 0), x_high = x − x_c above it (else 0) and high the
   indicator of the upper side. As in Simonsohn's code, b1 comes from the regression where
   x_c belongs to the first line and b2 from the one where it belongs to the second.
   Heteroskedasticity-consistent HC3 standard errors (MacKinnon & White 1985), t tests on
   the residual degrees of freedom.
3. **Robin Hood.** The first break is the median x of the flat region's observations; with
   its two t statistics, the break moves to the quantile |t2| / (|t1| + |t2|) of those x
   values, giving more observations to the weaker line. The regressions are run again there.
4. **Verdict.** The peak is interior (an inverted U) when the first slope is significantly
   positive *and* the second significantly negative, each tested one-sided at ``alpha``
   (default 0.05; ``alpha=0.025`` is Simonsohn's published criterion, two-sided p < .05 for
   slopes of opposite sign). A slope that cannot be estimated (fewer than two levels on
   its side) is not significant. Simulated with 7 levels × 10 paired runs, the default
   detects an inverted U of peak-to-edge height 1.35 noise sd in about 90 % of data sets
   and a flat curve in about 2 %; a rise to a plateau (the hardest null) in about 5 %.

With ``paired`` (the default), each run that was observed at two or more levels gets its own
intercept: run *i* has the same seed at every sweep point (and every context of one run is
seen by one agent), so the per-run intercepts take out the variance between seeds
(Simonsohn's test admits covariates).

For comparison, :func:`inverted_u_test` also fits the quadratic y = c0 + c1·x + c2·x² (same
covariates and HC3), with the vertex −c1 / (2 c2) when c2 < 0. The **peak's location** is the
level with the highest mean (and the quadratic's vertex), each with a percentile bootstrap
interval (Efron & Tibshirani 1993): runs are resampled with replacement within each level.

Input: a tidy table with one row per observation (a run at a level): the level ``x``, the
performance ``y``, the run id ``run``, and optional grouping columns ``by`` (e.g. the VTA
model). Output: one row per group.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd
import statsmodels.api as sm
from scipy import stats as sps

from neurocur.contract import require_columns

from .bootstrap import BOOTSTRAP_SEED, N_BOOT

__all__ = ["level_means", "two_lines", "quadratic_fit", "peak_location", "inverted_u_test"]

#: The reference of the test, as the output's ``test`` column names it.
TWO_LINES = "two-lines test (Simonsohn 2018), Robin Hood break, HC3"


def _clean(table: pd.DataFrame, x: str, y: str, run: str | None, needed_by: str):
    """The finite (x, y) observations as float arrays, and their run ids (None without ``run``)."""
    require_columns(table, [x, y, *([run] if run else [])], needed_by=needed_by)
    xv, yv = table[x].to_numpy(dtype=float), table[y].to_numpy(dtype=float)
    keep = np.isfinite(xv) & np.isfinite(yv)
    return xv[keep], yv[keep], (table[run].to_numpy()[keep] if run else None)


def level_means(
    table: pd.DataFrame, x: str, y: str, *, by: str | Sequence[str] | None = None, confidence: float = 0.95
) -> pd.DataFrame:
    """Mean of ``y`` per level of ``x`` (per group of ``by``), with Student's t interval over the runs.

    Columns: the ``by`` columns, ``x``, n, mean, sd, ci_low, ci_high (NaN for one run).

    Parameters
    ----------
    table : pandas.DataFrame
        One row per observation (a run at a level).
    x : str
        The column of the level.
    y : str
        The column averaged.
    by : str or sequence of str, optional
        The grouping columns (e.g. the model); None: one group.
    confidence : float
        Coverage of the t interval, in (0, 1).

    Returns
    -------
    pandas.DataFrame
        One row per group and level, the columns above.
    """
    groups = [] if by is None else ([by] if isinstance(by, str) else list(by))
    require_columns(table, [*groups, x, y], needed_by="level_means")
    out = table.groupby([*groups, x], sort=True)[y].agg(n="count", mean="mean", sd="std").reset_index()
    half = sps.t.ppf((1 + confidence) / 2, np.maximum(out["n"] - 1, 1)) * out["sd"] / np.sqrt(out["n"])
    out["ci_low"], out["ci_high"] = out["mean"] - half, out["mean"] + half
    return out


def _covariates(xv: np.ndarray, runs: np.ndarray | None, paired: bool) -> np.ndarray:
    """One indicator column per run observed at two or more levels (all but one: the intercept's)."""
    if not paired or runs is None:
        return np.empty((len(xv), 0))
    levels = pd.Series(xv).groupby(runs).nunique()
    kept = sorted(levels.index[levels >= 2])[1:]
    return np.column_stack([(runs == r).astype(float) for r in kept]) if kept else np.empty((len(xv), 0))


def _ols(y: np.ndarray, design: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """OLS coefficients, their HC3 standard errors and the residual degrees of freedom."""
    fit = sm.OLS(y, design).fit(cov_type="HC3")
    return np.asarray(fit.params), np.asarray(fit.bse), int(fit.df_resid)


def _line(xv: np.ndarray, yv: np.ndarray, covariates: np.ndarray, xc: float, which: int) -> dict:
    """Slope of line ``which`` (1: x <= xc, 2: x >= xc; the break belongs to the line tested) of
    the interrupted regression at ``xc``: slope, se, t, one-sided p (1: slope > 0; 2: slope < 0)."""
    low = xv <= xc if which == 1 else xv < xc
    high = ~low
    nan = {"slope": math.nan, "se": math.nan, "t": math.nan, "p": math.nan}
    if len(np.unique(xv[low if which == 1 else high])) < 2:
        return nan
    columns = {"intercept": np.ones_like(xv)}
    if len(np.unique(xv[low])) >= 2:
        columns["low"] = np.where(low, xv - xc, 0.0)
    if len(np.unique(xv[high])) >= 2:
        columns["high"] = np.where(high, xv - xc, 0.0)
    if low.any() and high.any():
        columns["jump"] = high.astype(float)
    design = np.column_stack([*columns.values(), covariates])
    if np.linalg.matrix_rank(design) < design.shape[1]:
        return nan
    beta, se, df = _ols(yv, design)
    k = list(columns).index("low" if which == 1 else "high")
    t = beta[k] / se[k] if se[k] > 0 else math.nan       # no residual variance: nothing to test
    return {"slope": beta[k], "se": se[k], "t": t, "p": float(sps.t.sf(t, df) if which == 1 else sps.t.cdf(t, df))}


def _interrupted(xv: np.ndarray, yv: np.ndarray, covariates: np.ndarray, xc: float) -> dict:
    """The two lines at the break ``xc`` (Simonsohn's two regressions, the break in the line tested)."""
    out = {"break_point": float(xc), "n_low": int((xv <= xc).sum()), "n_high": int((xv >= xc).sum())}
    for which in (1, 2):
        out.update({f"{k}{which}": v for k, v in _line(xv, yv, covariates, xc, which).items()})
    return out


def _level_stats(xv: np.ndarray, yv: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The sorted levels, each observation's level index, the counts and the means per level."""
    levels, index = np.unique(xv, return_inverse=True)
    counts = np.bincount(index).astype(float)
    return levels, index, counts, np.bincount(index, weights=yv) / counts


def _flat_region(xv: np.ndarray, yv: np.ndarray) -> np.ndarray:
    """The x of every observation in the flat region: among the middle 80 % of x (strictly between
    its 10th and 90th percentiles, so the break is never at an extreme), the levels whose mean
    plus one standard error exceeds the highest mean there."""
    levels, index, counts, means = _level_stats(xv, yv)
    dof = int((counts - 1).sum())
    if dof < 1:
        raise ValueError("the two-lines test needs repeated observations at some level (runs per level) "
                         "to estimate the flexible fit's standard error")
    se = np.sqrt(float(((yv - means[index]) ** 2).sum() / dof) / counts)
    lo, hi = np.quantile(xv, [0.1, 0.9])
    middle = (levels > lo) & (levels < hi)
    if not middle.any():
        middle[:] = True
    flat = middle & (means + se >= means[middle].max())
    return np.sort(xv[flat[index]])


def two_lines(
    table: pd.DataFrame, x: str, y: str, run: str | None = "run", *, alpha: float = 0.05, paired: bool = True
) -> dict:
    """Simonsohn's (2018) two-lines test of an interior peak of ``y`` over ``x`` (see the module docstring).

    Returns a dict: n, n_levels, break_point (the Robin Hood break x_c), n_low, n_high
    (observations on each side), slope1, se1, t1, p1 (one-sided, slope1 > 0), slope2, se2, t2,
    p2 (one-sided, slope2 < 0), interior_peak (p1 < alpha and p2 < alpha), alpha, test.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per observation (a run at a level); rows with a non-finite ``x`` or ``y`` are dropped.
    x : str
        The column of the level.
    y : str
        The column of the performance.
    run : str or None
        The column of the run id (for the run intercepts); None: no run intercepts.
    alpha : float
        Level of each one-sided slope test, in (0, 1).
    paired : bool
        Give each run observed at two or more levels its own intercept.

    Returns
    -------
    dict
        The entries above.

    Raises
    ------
    ValueError
        When ``alpha`` is outside (0, 1), ``x`` has fewer than 3 levels, no level is repeated,
        or a column is missing.
    """
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"two_lines: alpha must be in (0, 1), got {alpha}")
    xv, yv, runs = _clean(table, x, y, run, "two_lines")
    n_levels = len(np.unique(xv))
    if n_levels < 3:
        raise ValueError(f"two_lines needs at least 3 levels of {x!r}, got {n_levels}")
    covariates = _covariates(xv, runs, paired)
    flat = _flat_region(xv, yv)
    first = _interrupted(xv, yv, covariates, float(np.median(flat)))
    xc = first["break_point"]
    if np.isfinite(first["t1"]) and np.isfinite(first["t2"]) and abs(first["t1"]) + abs(first["t2"]) > 0:
        xc = float(np.quantile(flat, abs(first["t2"]) / (abs(first["t1"]) + abs(first["t2"]))))
    result = _interrupted(xv, yv, covariates, xc)
    interior = bool(result["p1"] < alpha and result["p2"] < alpha)   # NaN compares False
    return {"n": len(xv), "n_levels": n_levels, **result, "interior_peak": interior,
            "alpha": alpha, "test": TWO_LINES + (", run intercepts" if covariates.shape[1] else "")}


def quadratic_fit(table: pd.DataFrame, x: str, y: str, run: str | None = "run", *, paired: bool = True) -> dict:
    """The quadratic y = c0 + c1·x + c2·x² (+ run intercepts), HC3 standard errors.

    Returns a dict: quad_c1, quad_c2, quad_se2, quad_p (one-sided, c2 < 0), vertex
    (−c1 / (2 c2) when c2 < 0, else NaN).

    Parameters
    ----------
    table : pandas.DataFrame
        One row per observation (a run at a level); rows with a non-finite ``x`` or ``y`` are dropped.
    x : str
        The column of the level.
    y : str
        The column of the performance.
    run : str or None
        The column of the run id (for the run intercepts); None: no run intercepts.
    paired : bool
        Give each run observed at two or more levels its own intercept.

    Returns
    -------
    dict
        The entries above.
    """
    xv, yv, runs = _clean(table, x, y, run, "quadratic_fit")
    centre = xv.mean()
    xc = xv - centre
    design = np.column_stack([np.ones_like(xc), xc, xc**2, _covariates(xv, runs, paired)])
    beta, se, df = _ols(yv, design)
    c1 = beta[1] - 2 * beta[2] * centre
    return {"quad_c1": c1, "quad_c2": beta[2], "quad_se2": se[2],
            "quad_p": float(sps.t.cdf(beta[2] / se[2], df)) if se[2] > 0 else math.nan,
            "vertex": centre - beta[1] / (2 * beta[2]) if beta[2] < 0 else math.nan}


def peak_location(
    table: pd.DataFrame,
    x: str,
    y: str,
    *,
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> dict:
    """The level with the highest mean ``y`` and the quadratic's vertex, with percentile bootstrap
    intervals (runs resampled with replacement within each level, ``n_boot`` times, from ``seed``).

    Returns a dict: peak_level, peak_ci_low, peak_ci_high, vertex_ci_low, vertex_ci_high,
    vertex_defined (the share of resamples whose quadratic is concave; the vertex interval is
    over those).

    Parameters
    ----------
    table : pandas.DataFrame
        One row per observation (a run at a level); rows with a non-finite ``x`` or ``y`` are dropped.
    x : str
        The column of the level.
    y : str
        The column of the performance.
    n_boot : int
        Number of bootstrap resamples.
    confidence : float
        Coverage of the intervals, in (0, 1).
    seed : int
        Seed of the resamples.

    Returns
    -------
    dict
        The entries above.
    """
    xv, yv, _ = _clean(table, x, y, None, "peak_location")
    levels, index, counts, level_mean = _level_stats(xv, yv)
    groups = [yv[index == i] for i in range(len(levels))]
    rng = np.random.default_rng(seed)
    means = np.column_stack([g[rng.integers(0, len(g), size=(int(n_boot), len(g)))].mean(axis=1) for g in groups])
    # the design is the same in every resample (the counts per level do not change), so the
    # quadratic's coefficients are one linear map of the level means
    centre = float((counts * levels).sum() / counts.sum())
    basis = np.column_stack([np.ones_like(levels), levels - centre, (levels - centre) ** 2])
    gram = basis.T @ (counts[:, None] * basis)
    coef = np.linalg.solve(gram, (basis * counts[:, None]).T @ means.T)         # (3, n_boot)
    concave = coef[2] < 0
    vertex = centre - coef[1][concave] / (2 * coef[2][concave])
    q = [(1 - confidence) / 2, (1 + confidence) / 2]
    peaks = levels[np.argmax(means, axis=1)]
    v_low, v_high = np.quantile(vertex, q) if vertex.size else (math.nan, math.nan)
    p_low, p_high = np.quantile(peaks, q)
    return {"peak_level": float(levels[np.argmax(level_mean)]), "peak_ci_low": float(p_low),
            "peak_ci_high": float(p_high), "vertex_ci_low": float(v_low), "vertex_ci_high": float(v_high),
            "vertex_defined": float(concave.mean())}


def inverted_u_test(
    table: pd.DataFrame,
    x: str,
    y: str,
    run: str | None = "run",
    *,
    by: str | Sequence[str] | None = None,
    alpha: float = 0.05,
    paired: bool = True,
    n_boot: int = N_BOOT,
    confidence: float = 0.95,
    seed: int = BOOTSTRAP_SEED,
) -> pd.DataFrame:
    """The inverted-U analysis of ``y`` over ``x``, one row per group of ``by`` (e.g. per model).

    Columns: the ``by`` columns, x and y (the names analysed), then :func:`two_lines`'
    (n, n_levels, break_point, n_low, n_high, slope1, se1, t1, p1, slope2, se2, t2, p2,
    interior_peak, alpha, test), :func:`quadratic_fit`'s (quad_c1, quad_c2, quad_se2, quad_p,
    vertex) and :func:`peak_location`'s (peak_level, peak_ci_low, peak_ci_high, vertex_ci_low,
    vertex_ci_high, vertex_defined).

    Parameters
    ----------
    table : pandas.DataFrame
        One row per observation (a run at a level); rows with a non-finite ``x`` or ``y`` are dropped.
    x : str
        The column of the level.
    y : str
        The column of the performance.
    run : str or None
        The column of the run id (for the run intercepts); None: no run intercepts.
    by : str or sequence of str, optional
        The grouping columns (e.g. the model); None: one group.
    alpha : float
        Level of each one-sided slope test of ``two_lines``, in (0, 1).
    paired : bool
        Give each run observed at two or more levels its own intercept.
    n_boot : int
        Number of bootstrap resamples of ``peak_location``.
    confidence : float
        Coverage of the intervals, in (0, 1).
    seed : int
        Seed of the resamples.

    Returns
    -------
    pandas.DataFrame
        One row per group, the columns above.
    """
    groups = [] if by is None else ([by] if isinstance(by, str) else list(by))
    require_columns(table, groups, needed_by="inverted_u_test")
    parts = table.groupby(groups, sort=True) if groups else [((), table)]
    rows = []
    for key, part in parts:
        key = key if isinstance(key, tuple) else (key,)
        rows.append({**dict(zip(groups, key)), "x": x, "y": y,
                     **two_lines(part, x, y, run, alpha=alpha, paired=paired),
                     **quadratic_fit(part, x, y, run, paired=paired),
                     **peak_location(part, x, y, n_boot=n_boot, confidence=confidence, seed=seed)})
    return pd.DataFrame(rows)
