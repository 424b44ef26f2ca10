"""The two-lines test of an inverted U (Simonsohn 2018) against analytic cases."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from neurocur.analysis import inverted_u_test, level_means, peak_location, quadratic_fit, two_lines

LEVELS = np.arange(7.0)


def curve(f, *, runs=10, sd=0.5, run_sd=0.0, seed=0) -> pd.DataFrame:
    """``runs`` runs at each of 7 levels: y = f(x) + a run's offset (sd ``run_sd``) + noise (sd ``sd``)."""
    rng = np.random.default_rng(seed)
    x, run = np.repeat(LEVELS, runs), np.tile(np.arange(runs), len(LEVELS))
    return pd.DataFrame({"x": x, "run": run,
                         "y": f(x) + rng.normal(0, run_sd, runs)[run] + rng.normal(0, sd, len(x))})


def symmetric_noise(f, *, levels=LEVELS, runs=10, amplitude=0.01) -> pd.DataFrame:
    """``runs`` runs at each level: y = f(x) ± ``amplitude`` alternating over runs, so that every
    level mean is exactly f(x)."""
    x, run = np.repeat(levels, runs), np.tile(np.arange(runs), len(levels))
    return pd.DataFrame({"x": x, "run": run, "y": f(x) + amplitude * (-1.0) ** run})


def tent_with_symmetric_noise(runs=10):
    """y = x up to 3, 6 − x after, ± 0.01 alternating over runs: every level mean is exactly the tent."""
    return symmetric_noise(lambda x: np.minimum(x, 6 - x), runs=runs)


def test_the_two_lines_of_a_tent_are_its_slopes_and_its_break_is_its_peak():
    result = two_lines(tent_with_symmetric_noise(), "x", "y", paired=False)
    assert result["break_point"] == 3.0                       # the flat region is level 3 alone
    assert result["slope1"] == pytest.approx(1.0) and result["slope2"] == pytest.approx(-1.0)
    assert result["n_low"] == 40 and result["n_high"] == 40       # the break belongs to the line tested
    assert result["p1"] < 1e-10 and result["p2"] < 1e-10 and result["interior_peak"]


def test_a_true_inverted_u_is_detected():
    result = inverted_u_test(curve(lambda x: -0.3 * (x - 3) ** 2), "x", "y", n_boot=500).iloc[0]
    assert result["interior_peak"]
    assert result["slope1"] > 0 > result["slope2"] and result["p1"] < 0.001 and result["p2"] < 0.001
    assert 2.0 <= result["break_point"] <= 4.0
    assert result["quad_c2"] == pytest.approx(-0.3, abs=0.05) and result["vertex"] == pytest.approx(3.0, abs=0.2)
    assert result["peak_level"] == 3.0
    assert result["peak_ci_low"] <= 3.0 <= result["peak_ci_high"]
    assert result["vertex_ci_low"] < 3.0 < result["vertex_ci_high"] and result["vertex_defined"] == 1.0


@pytest.mark.parametrize("shape", [lambda x: 0.5 * x, lambda x: 0.3 * (x - 3) ** 2, lambda x: np.log1p(x)],
                         ids=["monotone", "U", "concave monotone"])
def test_a_monotone_curve_or_a_u_is_not_an_inverted_u(shape):
    result = two_lines(curve(shape, seed=1), "x", "y")
    assert not result["interior_peak"]


def test_a_concave_monotone_curve_fools_the_quadratic_but_not_the_two_lines():
    table = curve(np.log1p, sd=0.2, seed=2)
    assert quadratic_fit(table, "x", "y")["quad_p"] < 0.001        # "significant" negative x² term
    assert not two_lines(table, "x", "y")["interior_peak"]


def test_a_flat_curve_is_detected_no_more_often_than_alpha():
    hits = [two_lines(curve(np.zeros_like, sd=1.0, run_sd=1.0, seed=seed), "x", "y")["interior_peak"]
            for seed in range(200)]
    assert np.mean(hits) <= 0.05


def test_run_intercepts_take_out_the_variance_between_seeds():
    table = curve(lambda x: -0.1 * (x - 3) ** 2, sd=0.3, run_sd=3.0, seed=3)
    paired, unpaired = two_lines(table, "x", "y"), two_lines(table, "x", "y", paired=False)
    assert paired["interior_peak"] and not unpaired["interior_peak"]
    assert paired["test"].endswith("run intercepts") and not unpaired["test"].endswith("run intercepts")


def test_the_quadratic_vertex_is_exact_on_an_exact_parabola():
    x, run = np.repeat(LEVELS, 4), np.tile(np.arange(4), len(LEVELS))
    table = pd.DataFrame({"x": x, "run": run, "y": 1.0 - (x - 2.5) ** 2 + 0.01 * (-1.0) ** run})
    result = quadratic_fit(table, "x", "y", paired=False)
    assert result["quad_c2"] == pytest.approx(-1.0) and result["quad_c1"] == pytest.approx(5.0)
    assert result["vertex"] == pytest.approx(2.5)
    assert np.isnan(quadratic_fit(table.assign(y=-table["y"]), "x", "y")["vertex"])     # convex: no peak


def test_the_peak_interval_is_reproducible_and_resamples_within_levels():
    table = curve(lambda x: -0.05 * (x - 4) ** 2, sd=1.0, seed=4)
    first, again = peak_location(table, "x", "y", seed=1), peak_location(table, "x", "y", seed=1)
    assert first == again
    assert first["peak_ci_low"] < first["peak_ci_high"]                  # a shallow peak: wide interval
    exact = peak_location(tent_with_symmetric_noise(2), "x", "y", n_boot=200)
    assert exact["peak_level"] == exact["peak_ci_low"] == exact["peak_ci_high"] == 3.0


def test_one_row_per_group():
    table = pd.concat([curve(lambda x: -0.3 * (x - 3) ** 2).assign(model="peaked"),
                       curve(lambda x: 0.5 * x).assign(model="rising")], ignore_index=True)
    result = inverted_u_test(table, "x", "y", by="model", n_boot=200).set_index("model")
    assert result.loc["peaked", "interior_peak"] and not result.loc["rising", "interior_peak"]
    assert result.loc["rising", "peak_level"] == 6.0 and (result["n"] == 70).all()


def test_level_means_with_t_intervals():
    table = pd.DataFrame({"x": [1, 1, 1, 2, 2], "y": [1.0, 2.0, 3.0, 5.0, 7.0]})
    means = level_means(table, "x", "y").set_index("x")
    half = sps.t.ppf(0.975, 2) / np.sqrt(3)
    assert means.loc[1, "mean"] == 2.0 and means.loc[1, "ci_low"] == pytest.approx(2.0 - half)
    assert means.loc[2, "ci_high"] == pytest.approx(6.0 + sps.t.ppf(0.975, 1) * np.sqrt(2) / np.sqrt(2))


def test_a_constant_curve_has_nothing_to_test():
    result = inverted_u_test(curve(np.zeros_like, sd=0.0, runs=3), "x", "y", n_boot=50).iloc[0]
    assert np.isnan(result["p1"]) and np.isnan(result["p2"]) and np.isnan(result["quad_p"])
    assert not result["interior_peak"] and np.isnan(result["vertex"])


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="at least 3 levels"):
        two_lines(curve(np.zeros_like).query("x < 2"), "x", "y")
    with pytest.raises(ValueError, match="repeated observations"):
        two_lines(curve(np.zeros_like, runs=1), "x", "y")
    with pytest.raises(ValueError, match="'performance'"):
        inverted_u_test(curve(np.zeros_like), "x", "performance")
    with pytest.raises(ValueError, match="alpha"):
        two_lines(curve(np.zeros_like), "x", "y", alpha=0.0)


def test_the_break_level_belongs_to_the_line_tested():
    """A spike at the peak level: the peak is on both lines, so each is pulled to ±15.5 / 5 = ±3.1
    (least squares through 0, 1, 2, 10 over x = 0..3 and through 10, 2, 1, 0 over x = 3..6)."""
    spiked = symmetric_noise(lambda x: np.minimum(x, 6 - x) + np.where(x == 3, 7.0, 0.0))
    result = two_lines(spiked, "x", "y", paired=False)
    assert result["break_point"] == 3.0
    assert result["slope1"] == pytest.approx(3.1) and result["slope2"] == pytest.approx(-3.1)


def test_robin_hood_moves_the_break_toward_the_stronger_line():
    """A steep rise to a plateau over levels 2-4, then a gentle fall: the first break, at the plateau's
    median (3), gives the rise the larger t, so the final break moves below 3 and the weaker falling line
    gets the plateau's observations (Simonsohn 2018: the break at the plateau's z2 / (z1 + z2) quantile)."""
    means = np.array([0.0, 3.0, 6.0, 6.0, 6.0, 5.5, 5.0])
    plateau = symmetric_noise(lambda x: means[x.astype(int)], amplitude=0.3)
    result = two_lines(plateau, "x", "y", paired=False)
    assert 2.0 <= result["break_point"] < 3.0
    assert abs(result["t1"]) > abs(result["t2"])


def test_the_break_is_never_at_an_extreme_level():
    """A monotone rise over 11 levels: the flat region is searched strictly between the 10th and 90th
    percentiles of x (here exactly levels 1 and 9), so the break is at level 8, not 9."""
    rising = symmetric_noise(lambda x: x, levels=np.arange(11.0))
    assert np.quantile(rising["x"], [0.1, 0.9]).tolist() == [1.0, 9.0]
    result = two_lines(rising, "x", "y", paired=False)
    assert result["break_point"] == 8.0


def test_the_peak_intervals_shrink_as_runs_are_added():
    """Runs are resampled within each level, so the vertex interval narrows as 1/sqrt(runs): sixteen times
    the runs make it about a quarter as wide (0.24-0.31 over five data seeds)."""
    width = []
    for runs in (10, 160):
        result = peak_location(curve(lambda x: -0.3 * (x - 3) ** 2, runs=runs, sd=1.0), "x", "y", n_boot=2000)
        width.append(result["vertex_ci_high"] - result["vertex_ci_low"])
    assert 0.15 < width[1] / width[0] < 0.45
