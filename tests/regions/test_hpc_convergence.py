"""HPC's checks that a module has converged, not merely stopped moving: the ``converged``
rule over several successive error ratios (``drift_ratios``) and the slowness-order check
(``ordered``); docs/reproduction.md, "Learning times"."""

from __future__ import annotations

import numpy as np
import pytest
from bound_region import bound, minimal_world

from neurocur.contexts.base import Episode
from neurocur.regions.hpc import HPCROC, _slowness_ordered, extrapolated_drift

T = 200
SLOW = np.sin(2 * np.pi * np.arange(T) / 1000)
FAST = np.sin(2 * np.pi * 24 * np.arange(T) / 1000)


@pytest.mark.parametrize("history, expected", [
    ([[0.5, 0.5], [1.0, 1.0]], 0.5 / (1 - 0.5)),                           # one ratio: the old rule
    ([[0.5, 0.5], [1.0, 1.0], [2.0, 2.0]], 0.5 / (1 - 0.5)),               # two equal ratios
    ([[0.5, 0.5], [1.0, 1.0], [1.5, 1.5]], 0.5 / (1 - 2 / 3)),             # rho is the larger ratio
    ([[0.5, 0.5], [0.25, 0.25], [2.0, 2.0]], np.inf),                      # the drift grew at the last visit
    ([[0.5, 0.5], [1.0, 1.0], [0.75, 0.75]], np.inf),                      # ... or at the one before
    ([[0.5, 0.5], [1.0, 1.0], [np.nan, 2.0]], np.inf),                     # a state lacks its third error
])
def test_extrapolated_drift(history, expected):
    assert extrapolated_drift(history) == pytest.approx(expected, rel=1e-15)


def test_one_ratio_is_the_single_visit_extrapolation():
    """drift_ratios = 1: E / (1 − ρ), ρ = Σ this visit's errors / Σ the previous visit's."""
    rng = np.random.default_rng(0)
    now, before = rng.uniform(0, 1, 50), rng.uniform(1, 2, 50)
    rho = now.sum() / before.sum()
    assert extrapolated_drift([now, before]) == pytest.approx(now.mean() / (1 - rho), rel=1e-12)


def derivative(y):
    dy = np.full_like(y, np.nan)
    dy[1:] = np.diff(y, axis=0)
    return dy


def test_slowness_order():
    for y, ordered in [(np.column_stack([SLOW, FAST]), True), (np.column_stack([FAST, SLOW]), False),
                       (np.column_stack([SLOW, np.zeros(T)]), False)]:  # a constant output is not ordered
        assert _slowness_ordered(y, derivative(y)) is ordered


def test_slowness_order_leaves_out_unknown_rows():
    y = np.column_stack([SLOW, FAST])
    dy = derivative(y)
    y[50:], dy[50:] = np.nan, np.nan  # states not visited yet
    dy[10] = [100.0, 0.0]  # with it, the first output would be the faster ...
    assert not _slowness_ordered(y, dy)
    dy[10] = np.nan  # ... a derivative not known (a start) is left out
    assert _slowness_ordered(y, dy)


def region(**params):
    return bound(HPCROC, "HPC", world=minimal_world(1, T), n_states=T, threshold=0.3, freeze="converged", **params)


def visits(hpc, features_per_visit):
    """Pass over the same T states once per features array, until a module is stored;
    returns module_learned of each visit made."""
    learned = []
    for y in features_per_visit:
        _, stored, *_ = hpc.step(Episode(np.zeros((T, 1)), np.arange(T), 0), y, np.empty((T, 0, 2)))
        hpc.learn()
        learned.append(stored)
        if stored:
            break
    return learned


def test_the_order_is_the_contexts_over_the_states_latest_visits():
    """Two visits of 100 states each, joined as one episode with a start between them: the
    step at the start is not a derivative, and the order is taken over both visits' states."""
    hpc = region(ordered=True)
    slow = np.concatenate([SLOW[:100], SLOW[:100] + 5.0])
    fast = np.sin(2 * np.pi * 15 * np.arange(T) / 1000)  # Δ 0.009: above the slow output's, below 4/(T-1)
    episode = Episode(np.zeros((T, 1)), np.arange(T), 0, starts=np.array([0, 100]))
    hpc._keep_outputs(episode, np.column_stack([slow, fast]))
    assert hpc.ordered(0)
    joined = Episode(np.zeros((T, 1)), np.arange(T), 0)  # one segment: the step counts and makes it the fastest
    hpc._keep_outputs(joined, np.column_stack([slow, fast]))
    assert not hpc.ordered(0)
    assert hpc.state_outputs.shape == (1, T, 2) and np.isnan(hpc.state_derivatives[0, 0]).all()


@pytest.mark.parametrize("ordered, stored", [(False, True), (True, False)])
def test_ordered_vetoes_a_module_whose_slowest_output_is_the_faster(ordered, stored):
    """Outputs that stopped moving freeze under ``converged``; out of slowness order they do not when ``ordered``."""
    swapped = np.column_stack([FAST, SLOW])
    shrinking = [swapped * (1 + 0.5 ** k) for k in range(6)]  # the drift halves at every visit
    learned = visits(region(ordered=ordered), shrinking)
    assert any(learned) is stored


def test_more_ratios_wait_for_a_consistent_shrink():
    """Drifts 1, 0.1, then growing: one ratio (0.1) fires at the third visit, two ratios never do."""
    y0 = np.column_stack([SLOW, FAST])
    path = [y0, y0 + 1.0, y0 + 1.1, y0 + 1.3, y0 + 1.7]  # drifts 1, 0.1, 0.2, 0.4 per feature
    assert visits(region(drift_ratios=1), path) == [False, False, True]
    assert visits(region(drift_ratios=2), path) == [False] * 5
