"""CD-MISFA regions one at a time, against numbers computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from bound_region import bound, minimal_world

from neurocur.config import ConfigError
from neurocur.contexts.base import Episode
from neurocur.regions.hpc import HPCROC, HPCParams
from neurocur.regions.lc import EpsilonGreedyLC
from neurocur.regions.pfc import PFCLSPI, eq14_rate, transition_model
from neurocur.regions.sensory import SensoryWorld
from neurocur.regions.vta import LearningProgressVTA, NoveltyVTA

NAN = float("nan")


def make(cls, world, seed=0, **params):
    return bound(cls, world=world, seed=seed, **params)




# ------------------------------------------------------------------ HPC

Y = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])


def ep(states, context=0):
    states = np.asarray(states, dtype=np.int64)
    return Episode(frames=np.zeros((len(states), 1)), states=states, context=context)


def hpc_pass(hpc, episode, features, library=None):
    T = len(features)
    lib = np.empty((T, 0, 2)) if library is None else library
    out = hpc.step(episode, features, lib)
    hpc.learn()
    return out, dict(zip([p.name for p in hpc.probes], hpc.record()))


def test_hpc_errors_and_context_mean_freeze():
    hpc = make(HPCROC, minimal_world(), n_states=4, threshold=0.3, prune_min_weight=0.0)
    out, rec = hpc_pass(hpc, ep([0, 1, 2, 3]), Y)
    assert out[:2] == (False, False) and math.isnan(out[2])  # no cluster yet: errors undefined
    assert math.isnan(rec["error"]) and math.isnan(rec["episode_error"])
    shift = np.array([[0.2, 0.0], [0.0, 0.2], [0.0, 0.0], [0.1, 0.0]])
    # half the states: stored errors 0.2, 0.2; the other half missing -> no context_mean freeze
    out, rec = hpc_pass(hpc, ep([0, 1]), Y[:2] + shift[:2])
    assert rec["episode_error"] == pytest.approx(0.2) and rec["error"] == pytest.approx(0.2)
    assert out[:3] == (False, False, pytest.approx(0.2)) and math.isnan(out[3])  # no state visited twice yet
    # the other half: now every state has a stored error -> mean (0.2+0.2+0+0.1)/4 = 0.125 < 0.3
    out, rec = hpc_pass(hpc, ep([2, 3]), Y[2:] + shift[2:])
    assert rec["episode_error"] == pytest.approx(0.05) and rec["error"] == pytest.approx(0.125)
    assert out[:3] == (False, True, pytest.approx(0.125)) and rec["module_learned"] and rec["n_modules"] == 1
    assert len(hpc.library) == 1 and hpc.bank is None and np.isnan(hpc.stored).all()
    event = hpc.events[-1]
    assert event == {"event": "module_stored", "module": 0, "context": 0, "n_clusters": 8}


def test_hpc_progress_is_the_drop_at_the_visits_own_states():
    """``progress``: the mean drop of the stored error at the states the visit shows, since their
    previous visit; eq 11's decrease over the visit per frame, undiluted by the other states."""
    hpc = make(HPCROC, minimal_world(), n_states=4, threshold=0.01, prune_min_weight=0.0)
    hpc_pass(hpc, ep([0, 1, 2, 3]), Y)  # a cluster at Y in every state
    out, _ = hpc_pass(hpc, ep([0, 1, 2, 3]), Y + [0.2, 0.0])  # errors 0.2, none stored before: undefined
    assert out[2] == pytest.approx(0.2) and math.isnan(out[3])
    total = hpc.stored[0].sum()
    out, rec = hpc_pass(hpc, ep([1, 2]), Y[1:3] + [0.05, 0.0])  # clusters at Y and Y + 0.2: errors 0.05
    assert out[3] == pytest.approx(0.15)
    assert total - hpc.stored[0].sum() == pytest.approx(2 * out[3])  # eq 11's decrease over the visit
    assert 0.2 - rec["error"] == pytest.approx(out[3] * 2 / 4)  # the context mean's drop: diluted by 2 of 4 states
    out, _ = hpc_pass(hpc, ep([1, 3]), Y[[1, 3]] + [0.05, 0.0])  # state 1: 0.05 -> 0 (a cluster there now);
    assert out[3] == pytest.approx((0.05 + 0.15) / 2)  # state 3: 0.2 -> 0.05


def test_hpc_context_sum_and_episode_mean_rules():
    shifted = Y + np.array([0.1, 0.0])  # every state's error 0.1: mean 0.1 < 0.3, sum 0.4 > 0.3
    for rule, fires in (("context_mean", True), ("context_sum", False), ("episode_mean", True)):
        hpc = make(HPCROC, minimal_world(), n_states=4, freeze=rule)
        hpc_pass(hpc, ep([0, 1, 2, 3]), Y)
        out, _ = hpc_pass(hpc, ep([0, 1, 2, 3]), shifted)
        assert out[1] is fires, rule
    # episode_mean fires on a partial episode, context_mean does not
    for rule, fires in (("context_mean", False), ("episode_mean", True)):
        hpc = make(HPCROC, minimal_world(), n_states=4, freeze=rule)
        hpc_pass(hpc, ep([0, 1, 2, 3]), Y)
        hpc.stored[:] = NAN
        out, _ = hpc_pass(hpc, ep([0, 1]), Y[:2])
        assert out[1] is fires, rule
    # context_sum with small errors: 4 x 0.05 = 0.2 < 0.3
    hpc = make(HPCROC, minimal_world(), n_states=4, freeze="context_sum")
    hpc_pass(hpc, ep([0, 1, 2, 3]), Y)
    assert hpc_pass(hpc, ep([0, 1, 2, 3]), Y + np.array([0.05, 0.0]))[0][1] is True


def test_hpc_reward_error_modes():
    for mode, expected in (("context", 0.125), ("episode", 0.05)):
        hpc = make(HPCROC, minimal_world(), n_states=4, reward_error=mode, threshold=0.01)
        hpc_pass(hpc, ep([0, 1, 2, 3]), Y)
        hpc_pass(hpc, ep([0, 1]), Y[:2] + np.array([[0.2, 0.0], [0.0, 0.2]]))
        out, _ = hpc_pass(hpc, ep([2, 3]), Y[2:] + np.array([[0.0, 0.0], [0.1, 0.0]]))
        assert out[2] == pytest.approx(expected), mode


def test_hpc_pruning_gating_and_per_context_clusterers():
    for min_weight, kept in ((0.0, 8), (0.5, 4)):
        hpc = make(HPCROC, minimal_world(), n_states=4, prune_min_weight=min_weight)
        hpc_pass(hpc, ep([0, 1, 2, 3]), Y)  # one cluster per state, weight 0
        out, _ = hpc_pass(hpc, ep([0, 1, 2, 3]), Y)  # error 0 -> stored; second cluster (latest) added
        assert out[1] is True
        # the first cluster has weight 0 < 0.5 and is not the latest: pruned; the latest is always kept
        assert hpc.events[-1]["n_clusters"] == kept
    lib = Y[:, None, :] + np.array([0.0, 0.1])  # frozen module 0 sees error 0.1 < 0.3
    out, rec = hpc_pass(hpc, ep([0, 1, 2, 3]), np.zeros((4, 2)), lib)
    assert out[0] is True and rec["gating_module"] == 0 and rec["min_frozen_error"] == pytest.approx(0.1)
    assert hpc.bank.n_clusters_.sum() == 0  # familiar: the fresh bank did not learn
    # the same states of context 1 have their own clusterers: the frozen module knows nothing there
    out, rec = hpc_pass(hpc, ep([0, 1, 2, 3], context=1), np.zeros((4, 2)), lib)
    assert out[0] is False and rec["gating_module"] == -1 and math.isnan(rec["min_frozen_error"])
    # shared clusterers ("state"): a module learned in context 0 gates context 1
    shared = make(HPCROC, minimal_world(), n_states=4, clusterers="state")
    hpc_pass(shared, ep([0, 1, 2, 3]), Y)
    hpc_pass(shared, ep([0, 1, 2, 3]), Y)
    out, rec = hpc_pass(shared, ep([0, 1, 2, 3], context=1), np.zeros((4, 2)), Y[:, None, :])
    assert out[0] is True and rec["min_frozen_error"] == 0.0
    # gating lesion: never familiar, so module storage may fire again
    lesioned = make(HPCROC, minimal_world(), n_states=4, gating=False)
    lesioned.library = shared.library
    out, rec = hpc_pass(lesioned, ep([0, 1, 2, 3]), np.zeros((4, 2)), Y[:, None, :])
    assert out[0] is False and rec["min_frozen_error"] == 0.0 and rec["gating_module"] == -1


def test_hpc_parameter_validation_and_world_size():
    with pytest.raises(ConfigError, match="HPCParams: key 'freeze': expected one of 'context_mean', 'context_sum', "
                                          "'episode_mean', 'converged', got 'sum' \\(str\\)"):
        HPCParams(freeze="sum")
    with pytest.raises(ConfigError, match="key 'threshold': expected a number > 0"):
        HPCParams(threshold=0)
    with pytest.raises(ConfigError, match="key 'n_states': expected an integer >= 1, got 2.5"):
        HPCParams(n_states=2.5)
    with pytest.raises(ConfigError, match="key 'gating': expected a boolean"):
        HPCParams(gating=1)
    with pytest.raises(ValueError, match="smaller than the world's 4 context-states"):
        make(HPCROC, minimal_world(), n_states=3)


# ------------------------------------------------------------------ VTA


def test_vta_learning_progress_and_boredom():
    vta = make(LearningProgressVTA, minimal_world(3))
    sequence = [  # context, error, familiar, module_learned -> expected DA
        (0, NAN, False, False, 0.0),  # undefined
        (0, 5.0, False, False, 0.0),  # first defined value of context 0
        (1, 4.0, False, False, 0.0),  # first visit of context 1
        (0, 3.5, False, False, 1.5),  # 5.0 -> 3.5
        (0, 3.7, False, False, -0.2),
        (1, 1.0, True, False, -100.0),  # familiar: boredom
        (1, 0.5, False, False, 0.5),  # previous of context 1 was measured at the familiar visit
        (2, 9.0, False, True, 0.0),  # module stored: memory cleared after this pass
        (0, 2.0, False, False, 0.0),
        (0, 1.0, False, False, 1.0),
    ]
    for c, e, fam, learned, expected in sequence:
        assert vta.step(c, e, fam, learned) == (pytest.approx(expected),)
    vta = make(LearningProgressVTA, minimal_world(3), boredom=-7.0)
    assert vta.step(0, 1.0, True, False) == (-7.0,)


def test_vta_novelty():
    vta = make(NoveltyVTA, minimal_world(3), scale=2.0)
    das = [vta.step(c, NAN, True, False)[0] for c in (0, 0, 1, 0, 1)]
    np.testing.assert_allclose(das, [2.0, 2.0 / np.sqrt(2), 2.0, 2.0 / np.sqrt(3), 2.0 / np.sqrt(2)])


# ------------------------------------------------------------------ PFC


def q_by_value_iteration(P, R, gamma, n_iter=3000):
    Q = np.zeros_like(R)
    for _ in range(n_iter):
        Q = R + gamma * P @ Q.max(axis=1)
    return Q


def test_pfc_eq14_reward_model_and_lspi_values():
    alpha, gamma = 0.3, 0.8
    pfc = make(PFCLSPI, minimal_world(3), alpha=alpha, discount=gamma)
    P = transition_model(3)
    np.testing.assert_array_equal(P[:, 0], np.eye(3))
    np.testing.assert_array_equal(P[1, 1], [0.5, 0.0, 0.5])
    R3 = np.zeros((3, 2, 3))
    prev = None
    for context, da, action in [(0, 9.0, None), (0, 2.0, 0), (2, -1.0, 1), (1, 4.0, 1), (1, 3.0, 0), (1, -2.0, 0)]:
        q = pfc.step(context, da, action)[0]
        if prev is not None:
            R3[prev, action, context] = (1 - alpha) * R3[prev, action, context] + alpha * da  # eq 14
        prev = context
        R = (P * R3).sum(axis=2)
        np.testing.assert_allclose(pfc.model.R3, R3)
        np.testing.assert_allclose(q, q_by_value_iteration(P, R, gamma)[context], atol=1e-9)
    assert R3[1, 0, 1] == pytest.approx(0.3 * 3.0 * 0.7 + 0.3 * -2.0)
    assert R3[0, 1, 2] == pytest.approx(-0.3) and R3[0, 0, 0] == pytest.approx(0.6)


def test_pfc_eq14_as_a_sample_average():
    """``alpha = "sample_average"``: each entry R[o, a, o'] is the plain mean of the rewards it was given."""
    pfc = make(PFCLSPI, minimal_world(3), alpha="sample_average", discount=0.5)
    given: dict = {}
    prev = None
    rng = np.random.default_rng(3)
    for _ in range(60):
        context, action, da = int(rng.integers(3)), int(rng.integers(2)), float(rng.normal())
        pfc.step(context, da, action if prev is not None else None)
        if prev is not None:
            given.setdefault((prev, action, context), []).append(da)
        prev = context
    assert len(given) > 6
    for (o, a, o2), rewards in given.items():
        assert pfc.model.R3[o, a, o2] == pytest.approx(np.mean(rewards), abs=1e-12)
        assert pfc.model.N3[o, a, o2] == len(rewards)
    assert eq14_rate(0.2, 7) == 0.2 and eq14_rate("sample_average", 4) == 0.25
    with pytest.raises(ConfigError, match="'sample_average'"):
        make(PFCLSPI, minimal_world(3), alpha="mean")


# ------------------------------------------------------------------ LC


def run_lc(lc, contexts, qs, learned):
    rows = []
    for c, q, m in zip(contexts, qs, learned):
        action, nxt, _ = lc.step(c, np.asarray(q, dtype=float), m)
        rows.append((action, nxt, *lc.record()[2:]))
    return rows


def test_lc_epsilon_decay_reset_and_ne():
    lc = make(EpsilonGreedyLC, minimal_world(4), epsilon0=0.6, decay=0.9)
    n = 12
    learned = [False] * n
    learned[5] = True
    rows = run_lc(lc, [1] * n, [(2.0, 1.0)] * n, learned)
    eps = [r[2] for r in rows]
    expected = [0.6 * 0.9**k for k in range(5)] + [0.6 * 0.9**k for k in range(n - 5)]
    np.testing.assert_allclose(eps, expected)
    for (action, nxt, e, tonic, phasic), m in zip(rows, learned):
        assert tonic == pytest.approx(e / 2)  # Q_eng > Q_dis: g = 0
        if m:
            assert phasic == 1.0
        elif action == 0:
            assert nxt == 1 and phasic == pytest.approx(math.tanh(1.0))
        else:
            assert nxt != 1 and phasic == 0.0
    rows = run_lc(lc, [0, 0], [(1.0, 3.0), (1.0, 1.0)], [False, False])
    e0 = rows[0][2]
    assert rows[0][3] == pytest.approx(e0 / 2 + (1 - e0)) and rows[1][3] == pytest.approx(0.5)
    greedy = make(EpsilonGreedyLC, minimal_world(4), epsilon0=0.0)
    assert all(r[0] == 1 for r in run_lc(greedy, [2] * 20, [(0.0, 1.0)] * 20, [False] * 20))
    assert all(r[0] == 0 and r[4] == pytest.approx(math.tanh(0.5))
               for r in run_lc(greedy, [2] * 20, [(0.5, 0.0)] * 20, [False] * 20))


def test_lc_random_choices_are_uniform():
    lc = make(EpsilonGreedyLC, minimal_world(4), seed=3, **EpsilonGreedyLC.lesions["random"])
    n = 4000
    rows = run_lc(lc, [2] * n, [(5.0, 0.0)] * n, [False] * n)
    actions = np.array([r[0] for r in rows])
    nxt = np.array([r[1] for r in rows])
    assert np.all([r[2] == 1.0 for r in rows])
    assert abs(actions.mean() - 0.5) < 4.5 * np.sqrt(0.25 / n)
    counts = np.bincount(nxt[actions == 1], minlength=4)
    assert counts[2] == 0
    expected = (actions == 1).sum() / 3
    chi2 = ((counts[[0, 1, 3]] - expected) ** 2 / expected).sum()
    assert chi2 < 18.4  # chi-square, 2 degrees of freedom, p = 1e-4


# ------------------------------------------------------------------ sensory


def test_sensory_concatenates_episodes_when_staying(make_world):
    world = make_world(n_states=20, episode_len=5)
    s = make(SensoryWorld, world, episodes_on_engage=2, initial_context=1)
    first, c, _ = s.step(None)
    assert c == 1 and len(first.frames) == 5
    stay, c, _ = s.step(1)
    assert c == 1 and len(stay.frames) == 10 and list(stay.starts) == [0, 5]
    np.testing.assert_array_equal(stay.states, np.arange(5, 15))
    move, c, _ = s.step(0)
    assert c == 0 and len(move.frames) == 5 and list(move.starts) == [0]
    with pytest.raises(ValueError, match="initial_context must be < 3"):
        make(SensoryWorld, world, initial_context=3)


def test_hpc_converged_rule_extrapolates_the_remaining_drift():
    hpc = make(HPCROC, minimal_world(), n_states=4, threshold=0.3, freeze="converged", prune_min_weight=0.0)
    hpc_pass(hpc, ep([0, 1, 2, 3]), Y)  # clusters, no errors yet
    out, rec = hpc_pass(hpc, ep([0, 1, 2, 3]), Y + [0.2, 0.0])  # every error 0.2, no previous: no freeze
    assert rec["error"] == pytest.approx(0.2) and out[1] is False
    # errors shrink 0.2 -> 0.15: rho = 0.75, remaining drift 0.15 / 0.25 = 0.6 > 0.3
    out, rec = hpc_pass(hpc, ep([0, 1, 2, 3]), Y + [0.2, 0.0] + [0.15, 0.0])
    assert rec["error"] == pytest.approx(0.15) and out[1] is False
    # a context_mean freeze would fire here (0.15 < 0.3); 0.15 -> 0.03: rho = 0.2, 0.03 / 0.8 < 0.3
    out, rec = hpc_pass(hpc, ep([0, 1, 2, 3]), Y + [0.38, 0.0])
    assert rec["error"] == pytest.approx(0.03) and out[1] is True


def test_hpc_converged_rule_never_fires_when_errors_do_not_shrink():
    hpc = make(HPCROC, minimal_world(), n_states=4, threshold=0.3, freeze="converged")
    rng = np.random.default_rng(0)
    hpc_pass(hpc, ep([0, 1, 2, 3]), Y)
    fired = [hpc_pass(hpc, ep([0, 1, 2, 3]), Y + 0.05 * (k + 1) * rng.standard_normal((4, 2)))[0][1]
             for k in range(20)]
    assert not any(fired)


def test_hpc_spread_scale_divides_errors_by_the_feature_spread():
    for scale in (1.0, 0.01):  # the same geometry, features shrunk 100 times
        a = make(HPCROC, minimal_world(), n_states=4, threshold=0.3)
        s = make(HPCROC, minimal_world(), n_states=4, threshold=0.3, error_scale="spread")
        for hpc in (a, s):
            hpc_pass(hpc, ep([0, 1, 2, 3]), scale * Y)
        _, ra = hpc_pass(a, ep([0, 1, 2, 3]), scale * (Y + [0.2, 0.0]))
        _, rs = hpc_pass(s, ep([0, 1, 2, 3]), scale * (Y + [0.2, 0.0]))
        assert ra["episode_error"] == pytest.approx(0.2 * scale)
        # spread of Y about its mean: sqrt(mean ||y - (0.5, 0.5)||^2) = sqrt(0.5)
        assert rs["episode_error"] == pytest.approx(0.2 / math.sqrt(0.5))
