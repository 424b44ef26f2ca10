"""Paired tests, bootstrap intervals and the multiple-comparison adjustment, against scipy and
statsmodels on data whose answers are known (textbook examples, counts worked out by hand)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from neuro_tables import results_of
from scipy import stats as sps
from statsmodels.stats.multitest import multipletests

from neurocur.analysis import (
    BOOTSTRAP_SEED,
    COMPARE_COLUMNS,
    adjust_pvalues,
    bootstrap_ci,
    compare,
    compare_conditions,
    mcnemar_exact,
    paired_bootstrap_ci,
    per_run,
    unpaired_bootstrap_ci,
    wilcoxon_signed_rank,
)

# --- Wilcoxon signed-rank ---------------------------------------------------------------------

# Hollander & Wolfe (1999), Nonparametric Statistical Methods, Table 3.1 (Hamilton depression
# scale, first and second visit of 9 patients), the example of R's ?wilcox.test:
# V = T+ = 40, one-sided p = 10/512 = 0.01953, so two-sided p = 20/512.
DEPRESSION_X = [1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30]
DEPRESSION_Y = [0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29]


def test_wilcoxon_textbook_example():
    result = wilcoxon_signed_rank(DEPRESSION_X, DEPRESSION_Y)
    assert result["statistic"] == 5.0                      # min(T+, T-) = min(40, 5)
    assert result["p_value"] == pytest.approx(20 / 512, rel=1e-12)
    assert result["effect_size"] == pytest.approx((40 - 5) / 45)
    assert result["n_nonzero"] == 9
    assert result["test"] == "Wilcoxon signed-rank (paired by run, n=9 pairs; exact)"
    direct = sps.wilcoxon(DEPRESSION_X, DEPRESSION_Y)
    assert (result["statistic"], result["p_value"]) == (direct.statistic, direct.pvalue)
    assert wilcoxon_signed_rank(DEPRESSION_Y, DEPRESSION_X)["effect_size"] == pytest.approx(-35 / 45)


def test_wilcoxon_ties_and_a_zero_by_hand():
    # d = [1, 1, 2, 0, -1]: the zero is dropped; |d| ranks 2, 2, 4, 2 (three tied 1s), so
    # T+ = 8, T- = 2. Of the 16 sign flips, T+ <= 2 or >= 8 in 8: two-sided p = 1/2.
    x, y = [3, 4, 5, 7, 2], [2, 3, 3, 7, 3]
    result = wilcoxon_signed_rank(x, y)
    assert result["statistic"] == 2.0
    assert result["p_value"] == pytest.approx(0.5)
    assert result["effect_size"] == pytest.approx((8 - 2) / 10)
    assert result["n_nonzero"] == 4
    assert "1 zero dropped" in result["test"] and "exact sign-flip, ties" in result["test"]
    direct = sps.wilcoxon(x, y)
    assert result["p_value"] == pytest.approx(float(direct.pvalue)) and result["statistic"] == direct.statistic


def test_wilcoxon_matches_scipy_with_the_normal_approximation():
    rng = np.random.default_rng(7)
    x = rng.integers(0, 4, 30).astype(float)           # many ties and zeros: the normal approximation
    y = rng.integers(0, 3, 30).astype(float)
    result = wilcoxon_signed_rank(x, y)
    direct = sps.wilcoxon(x, y)
    assert result["statistic"] == direct.statistic
    assert result["p_value"] == pytest.approx(float(direct.pvalue), rel=1e-12)
    assert "normal approx." in result["test"] and result["n_nonzero"] == int((x != y).sum())


@pytest.mark.parametrize("n", [5, 30])
def test_wilcoxon_all_differences_zero_gives_p_one(n):
    x = np.arange(n, dtype=float)
    result = wilcoxon_signed_rank(x, x)
    assert (result["statistic"], result["p_value"], result["effect_size"], result["n_nonzero"]) == (0.0, 1.0, 0.0, 0)
    assert "all differences zero: p = 1" in result["test"]
    assert math.isnan(wilcoxon_signed_rank([], [])["p_value"])


# --- McNemar exact ----------------------------------------------------------------------------

def _binary_pairs(both_yes, a_only, b_only, both_no):
    x = [True] * both_yes + [True] * a_only + [False] * b_only + [False] * both_no
    y = [True] * both_yes + [False] * a_only + [True] * b_only + [False] * both_no
    return np.array(x), np.array(y)


def test_mcnemar_exact_is_the_binomial_test_of_the_discordant_pairs():
    x, y = _binary_pairs(5, 1, 6, 10)
    result = mcnemar_exact(x, y)
    # 7 discordant pairs, 1 against 6: two-sided binomial p = 2 * (1 + 7) / 2**7 = 0.125
    assert result["p_value"] == pytest.approx(0.125, rel=1e-12)
    assert result["p_value"] == pytest.approx(sps.binomtest(1, 7, 0.5).pvalue, rel=1e-12)
    assert result["statistic"] == 1.0 and result["n_nonzero"] == 7
    assert result["effect_size"] == pytest.approx(1 / 6)
    assert result["difference"] == pytest.approx((1 - 6) / 22)
    assert result["test"] == "McNemar exact (paired by run, n=22 pairs, 7 discordant)"


def test_mcnemar_exact_edges():
    x, y = _binary_pairs(3, 7, 0, 2)
    result = mcnemar_exact(x, y)
    assert result["p_value"] == pytest.approx(2 / 2**7) and result["effect_size"] == math.inf
    x, y = _binary_pairs(3, 0, 0, 2)
    result = mcnemar_exact(x, y)
    assert result["p_value"] == 1.0 and math.isnan(result["effect_size"]) and result["difference"] == 0.0


# --- bootstrap --------------------------------------------------------------------------------

def _sample(n, seed=0, mean=5.0, sd=1.0):
    """n values with exactly the given mean and sd."""
    z = np.random.default_rng(seed).standard_normal(n)
    return mean + sd * (z - z.mean()) / z.std(ddof=1)


def test_bootstrap_ci_covers_the_mean_and_shrinks_with_more_runs():
    small, large = bootstrap_ci(_sample(20)), bootstrap_ci(_sample(500))
    for low, high in (small, large):
        assert low < 5.0 < high
    # the percentile interval of a mean is about mean ± 1.96 sd / sqrt(n)
    assert small[1] - small[0] == pytest.approx(2 * 1.96 / np.sqrt(20), rel=0.2)
    assert large[1] - large[0] == pytest.approx(2 * 1.96 / np.sqrt(500), rel=0.2)
    assert large[1] - large[0] < (small[1] - small[0]) / 3
    narrower = bootstrap_ci(_sample(20), confidence=0.5)
    assert small[0] < narrower[0] < narrower[1] < small[1]


def test_bootstrap_ci_is_reproducible_for_a_seed():
    x = _sample(25)
    assert bootstrap_ci(x) == bootstrap_ci(x) == bootstrap_ci(x, seed=BOOTSTRAP_SEED)
    assert bootstrap_ci(x, seed=1) == bootstrap_ci(x, seed=1) != bootstrap_ci(x)
    assert bootstrap_ci(x, n_boot=500) != bootstrap_ci(x)
    assert all(math.isnan(v) for v in bootstrap_ci([math.nan]))
    assert bootstrap_ci([3.0]) == (3.0, 3.0)
    with pytest.raises(ValueError, match="n_boot"):
        bootstrap_ci(x, n_boot=0)


def test_paired_bootstrap_keeps_the_shared_baseline():
    baseline = np.arange(30) * 10.0
    x, y = baseline + 1.0 + 0.1 * _sample(30, 1, 0.0), baseline + 0.1 * _sample(30, 2, 0.0)
    paired, unpaired = paired_bootstrap_ci(x, y), unpaired_bootstrap_ci(x, y)
    assert paired["difference"][0] < 1.0 < paired["difference"][1]
    assert paired["difference"][1] - paired["difference"][0] < 0.2
    assert unpaired["difference"][1] - unpaired["difference"][0] > 30      # the baseline's spread
    assert unpaired["a"] == bootstrap_ci(x)


# --- multiple comparisons ---------------------------------------------------------------------

RAW_P = [0.01, 0.04, 0.03, 0.2, 0.001, math.nan]


@pytest.mark.parametrize(("method", "name"), [("holm", "holm"), ("bh", "fdr_bh"), ("fdr_bh", "fdr_bh")])
def test_adjusted_p_values_are_statsmodels(method, name):
    table = adjust_pvalues(pd.DataFrame({"p_value": RAW_P}), method)
    expected = multipletests(RAW_P[:-1], method=name)[1]
    np.testing.assert_allclose(table["p_adjusted"].iloc[:-1], expected, rtol=1e-12)
    assert (table["p_adjusted"].iloc[:-1] >= table["p_value"].iloc[:-1]).all()
    assert math.isnan(table["p_adjusted"].iloc[-1])
    assert (table["adjustment"] == name).all() and (table["n_tests"] == 5).all()


def test_holm_by_hand_and_no_adjustment():
    # Holm: sorted p 0.001, 0.01, 0.03, 0.04, 0.2 times 5, 4, 3, 2, 1, then the running maximum
    table = adjust_pvalues(pd.DataFrame({"p_value": RAW_P[:-1]}))
    np.testing.assert_allclose(table["p_adjusted"], [0.04, 0.09, 0.09, 0.2, 0.005])
    plain = adjust_pvalues(pd.DataFrame({"p_value": RAW_P[:-1]}), None)
    assert plain["p_adjusted"].tolist() == RAW_P[:-1] and (plain["adjustment"] == "none").all()
    with pytest.raises(ValueError, match="unknown p-value adjustment"):
        adjust_pvalues(pd.DataFrame({"p_value": RAW_P}), "bonferonni")


# --- compare: paired and unpaired -------------------------------------------------------------

#: compare() of the per-run table of the hand-made results folder before pairing was the default
#: (Mann–Whitney U / Fisher exact): statistic, p_value, effect_size per metric.
UNPAIRED_BEFORE = {
    "n_modules": (11.5, 0.07182815632096821, 0.9166666666666667),
    "n_learned": (11.5, 0.06396891699082884, 0.9166666666666667),
    "gated_sources": (11.5, 0.061368829139402156, 0.9166666666666667),
    "kendall_tau": (4.0, 0.2356799134290376, 1.0),
    "first_ok": (math.inf, 0.14285714285714285, math.inf),
    "second_ok": (math.inf, 0.14285714285714285, math.inf),
    "third_ok": (math.inf, 0.4285714285714286, math.inf),
    "exact_order": (math.inf, 0.4285714285714286, math.inf),
    "unlearnable_stored": (math.inf, 1.0, math.inf),
}


def test_unpaired_option_keeps_the_numbers_of_before(tables):
    result = compare(per_run(results_of(*tables)), "curious", "random_switching", paired=False).set_index("metric")
    assert list(result.index) == list(UNPAIRED_BEFORE)
    for metric, (statistic, p, effect) in UNPAIRED_BEFORE.items():
        row = result.loc[metric]
        assert (row["statistic"], row["p_value"], row["effect_size"]) == pytest.approx((statistic, p, effect), rel=1e-12)
    assert result.loc["gated_sources", "method"] == "mann_whitney_u"
    assert result.loc["gated_sources", "test"] == "Mann–Whitney U (unpaired, n=4 vs 3)"
    assert result.loc["exact_order", "test"] == "Fisher exact (unpaired, n=4 vs 3)"
    assert result["n_pairs"].isna().all()


def test_compare_pairs_by_run_and_drops_the_unpaired_run(tables):
    runs = per_run(results_of(*tables))
    result = compare(runs, "curious", "random_switching", metric=["gated_sources", "exact_order"])
    assert list(result.columns) == COMPARE_COLUMNS
    gated, exact = result.iloc[0], result.iloc[1]
    # curious runs 0..3 gate 3, 3, 3, 1; random runs 0..2 gate 0, 1, 0: run 3 has no pair
    assert (gated["n_a"], gated["n_b"], gated["n_pairs"], gated["n_nonzero"]) == (4, 3, 3, 3)
    assert gated["test"] == "Wilcoxon signed-rank (paired by run, n=3 pairs; exact sign-flip, ties)"
    direct = sps.wilcoxon([3, 3, 3], [0, 1, 0])
    assert (gated["statistic"], gated["p_value"]) == (direct.statistic, pytest.approx(direct.pvalue))
    assert gated["p_value"] == pytest.approx(0.25)                 # all 3 differences positive: 2/2**3
    assert (gated["value_a"], gated["value_b"], gated["difference"]) == pytest.approx((3.0, 1 / 3, 8 / 3))
    assert gated["effect"] == "matched_pairs_rank_biserial" and gated["effect_size"] == 1.0
    # exact order: curious runs 0..2 True, False, True; random all False: 2 discordant pairs
    assert exact["method"] == "mcnemar_exact" and exact["n_nonzero"] == 2 and exact["p_value"] == 0.5
    assert exact["effect_size"] == math.inf and exact["difference"] == pytest.approx(2 / 3)
    assert result["p_adjusted"].tolist() == pytest.approx(multipletests(result["p_value"], method="holm")[1].tolist())
    assert (result["adjustment"] == "holm").all() and (result["n_tests"] == 2).all()
    assert gated["ci_diff_low"] <= gated["difference"] <= gated["ci_diff_high"]


def test_pairing_matters_with_a_strong_per_run_baseline():
    # every run has its own world: a baseline from 0 to 190 shared by both conditions;
    # condition a is one unit above b on every run, far below the spread between runs
    baseline = np.arange(20) * 10.0
    jitter = np.random.default_rng(3).uniform(-0.3, 0.3, (2, 20))
    runs = pd.DataFrame({"condition": ["a"] * 20 + ["b"] * 20, "run": [*range(20), *range(20)],
                         "score": np.concatenate([baseline + 1.0 + jitter[0], baseline + jitter[1]])})
    paired = compare(runs, "a", "b", metric="score").iloc[0]
    unpaired = compare(runs, "a", "b", metric="score", paired=False).iloc[0]
    assert paired["p_value"] < 0.01 < 0.5 < unpaired["p_value"]
    assert paired["p_value"] == pytest.approx(2 / 2**20)             # every difference positive, exact
    assert paired["ci_diff_low"] > 0.5 and unpaired["ci_diff_low"] < 0


def test_compare_paired_needs_one_row_per_run():
    runs = pd.DataFrame({"condition": ["a", "a", "b", "b"], "score": [1.0, 2.0, 0.0, 1.0]})
    with pytest.raises(ValueError, match="'run' column"):
        compare(runs, "a", "b", metric="score")
    assert compare(runs, "a", "b", metric="score", paired=False).iloc[0]["n_a"] == 2
    with pytest.raises(ValueError, match="more than once"):
        compare(runs.assign(run=[0, 0, 0, 1]), "a", "b", metric="score")


def test_compare_conditions_adjusts_over_every_row():
    rng = np.random.default_rng(5)
    base = rng.normal(0, 5, 12)
    runs = pd.DataFrame({"condition": np.repeat(["ref", "x", "y"], 12), "run": np.tile(np.arange(12), 3),
                         "score": np.concatenate([base, base + rng.normal(1, 1, 12), base + rng.normal(0, 1, 12)]),
                         "hit": np.concatenate([np.ones(12, bool), rng.random(12) < 0.3, rng.random(12) < 0.9])})
    table = compare_conditions(runs, "ref", metric=["score", "hit"])
    assert table[["a", "b", "metric"]].values.tolist() == [
        ["ref", "x", "score"], ["ref", "x", "hit"], ["ref", "y", "score"], ["ref", "y", "hit"]]
    expected = multipletests(table["p_value"], method="holm")[1]
    np.testing.assert_allclose(table["p_adjusted"], expected)
    single = compare(runs, "ref", "x", metric="score", adjust=None).iloc[0]
    assert table.iloc[0]["p_value"] == single["p_value"] and single["p_adjusted"] == single["p_value"]
    bh = compare_conditions(runs, "ref", metric=["score", "hit"], adjust="bh")
    np.testing.assert_allclose(bh["p_adjusted"], multipletests(bh["p_value"], method="fdr_bh")[1])
