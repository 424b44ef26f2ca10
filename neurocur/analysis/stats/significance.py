"""Two-sample tests on per-run values: paired by run (the default of the study) or unpaired.

Run *i* of every condition and sweep point uses the same seed, hence the same world (mixing
matrices, clock offsets, first context), so the runs of two conditions come in pairs and a
comparison tests the run-paired differences:

* numbers: **Wilcoxon signed-rank** test (Wilcoxon 1945) on the differences ``a − b``
  (:func:`wilcoxon_signed_rank`), effect = matched-pairs rank-biserial correlation
  (Kerby 2014);
* yes/no outcomes: **McNemar's exact test** (McNemar 1947) on the discordant pairs
  (:func:`mcnemar_exact`), i.e. the two-sided binomial test of ``n_ab`` of ``n_ab + n_ba``
  against 1/2; effects = the difference in proportions and the odds ratio of the
  discordant pairs ``n_ab / n_ba``.

For data that are not paired, :func:`mann_whitney` (Mann & Whitney 1947) and
:func:`fisher_exact` (Fisher 1922) are the tests :func:`~neurocur.analysis.stats.comparison.compare`
used before pairing was the default; their numbers are unchanged.

Every function returns a dict with the keys ``method`` (a short code), ``test`` (what was
done, in words, with the sample sizes), ``statistic``, ``p_value``, ``effect`` (its name)
and ``effect_size``, plus ``n_nonzero`` for the paired tests (pairs with a non-zero
difference: Wilcoxon's ranked pairs, McNemar's discordant pairs).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats as sps
from statsmodels.stats.contingency_tables import mcnemar

__all__ = ["TESTS", "wilcoxon_signed_rank", "mcnemar_exact", "mann_whitney", "fisher_exact"]

#: Each test's name and reference, by the ``method`` code the functions return.
TESTS = {
    "wilcoxon": ("Wilcoxon signed-rank", "Wilcoxon 1945"),
    "mcnemar_exact": ("McNemar exact", "McNemar 1947"),
    "mann_whitney_u": ("Mann–Whitney U", "Mann & Whitney 1947"),
    "fisher_exact": ("Fisher exact", "Fisher 1922"),
}

#: scipy's ``method="auto"`` switches from the exact null distribution to the normal one above this many pairs
_EXACT_MAX = 50
#: ... and, with ties or zero differences, enumerates all 2**n sign flips up to this many pairs
_PERMUTATION_MAX = 13


def _pairs(n: int) -> str:
    return f"n={n} pair{'' if n == 1 else 's'}"


def _paired_arrays(x, y) -> tuple[np.ndarray, np.ndarray]:
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"a paired test needs two 1-d arrays of the same length, got shapes {x.shape} and {y.shape}")
    return x, y


def wilcoxon_signed_rank(x, y) -> dict:
    """Two-sided Wilcoxon signed-rank test (Wilcoxon 1945) of the paired differences ``x − y``.

    Zero differences are dropped before ranking (Wilcoxon's own rule, scipy's
    ``zero_method="wilcox"``); tied ``|d|`` get their average rank. The p-value is scipy's
    :func:`scipy.stats.wilcoxon` with the method its ``"auto"`` chooses, named in ``test``:

    * no ties and no zero difference, at most 50 pairs: the exact null distribution;
    * ties or zeros, at most 13 pairs: the exact sign-flip distribution (all 2**n flips);
    * otherwise the normal approximation with the tie correction (scipy's default: no
      continuity correction).

    **All differences zero** (the two conditions gave the same value on every run, e.g.
    a parameter the condition never reads): every sign flip gives the same statistic, so
    the exact p-value is 1; returned as statistic 0, p = 1, effect 0 (scipy would give
    NaN with the normal approximation). No pairs at all: NaN.

    ``statistic`` is scipy's two-sided statistic min(T+, T−); ``effect_size`` is the
    matched-pairs rank-biserial correlation (T+ − T−)/(T+ + T−) over the non-zero
    differences (Kerby 2014): +1 when ``x`` exceeds ``y`` on every pair that differs.

    Parameters
    ----------
    x, y : array_like
        The two conditions' values, paired by position (1-d, of the same length).

    Returns
    -------
    dict
        ``method``, ``statistic``, ``p_value``, ``effect``, ``effect_size``, ``n_nonzero`` and ``test`` (in words).
    """
    x, y = _paired_arrays(x, y)
    n = len(x)
    d = x - y
    nonzero = d[d != 0]
    out = {"method": "wilcoxon", "statistic": math.nan, "p_value": math.nan,
           "effect": "matched_pairs_rank_biserial", "effect_size": math.nan, "n_nonzero": len(nonzero)}
    name = "Wilcoxon signed-rank (paired by run"
    if n == 0:
        return {**out, "test": f"{name}, no pairs)"}
    if len(nonzero) == 0:
        return {**out, "test": f"{name}, {_pairs(n)}, all differences zero: p = 1)",
                "statistic": 0.0, "p_value": 1.0, "effect_size": 0.0}
    ranks = sps.rankdata(np.abs(nonzero))
    t_plus, t_minus = ranks[nonzero > 0].sum(), ranks[nonzero < 0].sum()
    ties = len(np.unique(np.abs(nonzero))) < len(nonzero)
    if not ties and len(nonzero) == n and n <= _EXACT_MAX:
        method, how = "exact", "exact"
    elif n <= _PERMUTATION_MAX:
        method, how = sps.PermutationMethod(), "exact sign-flip"
    else:
        method, how = "asymptotic", "normal approx."
    result = sps.wilcoxon(x, y, zero_method="wilcox", alternative="two-sided", method=method)
    zeros = f", {n - len(nonzero)} zero dropped" if len(nonzero) < n else ""
    return {**out, "test": f"{name}, {_pairs(n)}{zeros}; {how}{', ties' if ties else ''})",
            "statistic": float(result.statistic), "p_value": float(result.pvalue),
            "effect_size": float((t_plus - t_minus) / (t_plus + t_minus))}


def mcnemar_exact(x, y) -> dict:
    """McNemar's exact test (McNemar 1947) of paired yes/no outcomes ``x`` and ``y``.

    Only the discordant pairs count: ``n_ab`` (yes in ``x``, no in ``y``) and ``n_ba``. The
    p-value is statsmodels' ``mcnemar(table, exact=True)``: the two-sided binomial test of
    min(n_ab, n_ba) of n_ab + n_ba at 1/2 (equal to :func:`scipy.stats.binomtest`'s). No
    discordant pair gives p = 1. ``statistic`` = min(n_ab, n_ba); ``effect_size`` = the
    odds ratio of the discordant pairs n_ab / n_ba (0 or inf at the edges, NaN without
    discordant pairs); ``difference`` = n_ab/n − n_ba/n, the difference in proportions.

    Parameters
    ----------
    x, y : array_like of bool
        The two conditions' values, paired by position (1-d, of the same length).

    Returns
    -------
    dict
        ``method``, ``statistic``, ``p_value``, ``effect``, ``effect_size``, ``n_nonzero``, ``n_ab``, ``n_ba``, ``difference``
        and ``test`` (in words).
    """
    x, y = _paired_arrays(x, y)
    xb, yb = x.astype(bool), y.astype(bool)
    n = len(x)
    n_ab, n_ba = int((xb & ~yb).sum()), int((~xb & yb).sum())
    out = {"method": "mcnemar_exact", "effect": "discordant_odds_ratio", "n_nonzero": n_ab + n_ba,
           "n_ab": n_ab, "n_ba": n_ba}
    if n == 0:
        return {**out, "test": "McNemar exact (paired by run, no pairs)", "statistic": math.nan,
                "p_value": math.nan, "effect_size": math.nan, "difference": math.nan}
    table = [[int((xb & yb).sum()), n_ab], [n_ba, int((~xb & ~yb).sum())]]
    result = mcnemar(table, exact=True)
    if n_ba:
        ratio = n_ab / n_ba
    else:
        ratio = math.inf if n_ab else math.nan
    return {**out, "test": f"McNemar exact (paired by run, {_pairs(n)}, {n_ab + n_ba} discordant)",
            "statistic": float(result.statistic), "p_value": float(result.pvalue),
            "effect_size": ratio, "difference": (n_ab - n_ba) / n}


def mann_whitney(x, y) -> dict:
    """Two-sided Mann–Whitney U test (Mann & Whitney 1947) of two independent samples (NaN dropped).

    ``statistic`` = U of ``x`` (scipy's); ``effect_size`` = rank-biserial correlation
    2U/(n_x n_y) − 1, +1 when every value of ``x`` exceeds every value of ``y``.

    Parameters
    ----------
    x, y : array_like
        The two independent samples (NaN dropped).

    Returns
    -------
    dict
        ``method``, ``statistic``, ``p_value``, ``effect``, ``effect_size`` and ``test`` (in words).
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    x, y = x[~np.isnan(x)], y[~np.isnan(y)]
    out = {"method": "mann_whitney_u", "test": f"Mann–Whitney U (unpaired, n={len(x)} vs {len(y)})",
           "statistic": math.nan, "p_value": math.nan, "effect": "rank_biserial", "effect_size": math.nan}
    if len(x) and len(y):
        result = sps.mannwhitneyu(x, y, alternative="two-sided")
        out.update(statistic=float(result.statistic), p_value=float(result.pvalue),
                   effect_size=2.0 * result.statistic / (len(x) * len(y)) - 1.0)
    return out


def fisher_exact(x, y) -> dict:
    """Two-sided Fisher's exact test (Fisher 1922) of two independent samples of yes/no outcomes.

    ``statistic`` and ``effect_size`` = the sample odds ratio (x_yes·y_no)/(x_no·y_yes),
    which can be 0 or inf.

    Parameters
    ----------
    x, y : array_like of bool
        The two independent samples.

    Returns
    -------
    dict
        ``method``, ``statistic``, ``p_value``, ``effect``, ``effect_size`` and ``test`` (in words).
    """
    x, y = np.asarray(x, dtype=bool), np.asarray(y, dtype=bool)
    kx, ky = int(x.sum()), int(y.sum())
    result = sps.fisher_exact([[kx, len(x) - kx], [ky, len(y) - ky]])
    return {"method": "fisher_exact", "test": f"Fisher exact (unpaired, n={len(x)} vs {len(y)})",
            "statistic": float(result.statistic), "p_value": float(result.pvalue),
            "effect": "odds_ratio", "effect_size": float(result.statistic)}
