"""Mechanisms of the synthetic experiment (section 4.1), asserted on the running circuit.

Not outcome statistics: each test drives ``neurocur/circuits/cd_misfa.toml`` on a
``SyntheticWorld`` through a fixed schedule of contexts (a scripted LC in place of the
epsilon-greedy one) or with LC lesioned, and checks one mechanism:

- a module learned on S-A freezes and then gates S-A's contexts: a later episode is
  familiar (boredom DA, no training) exactly when the frozen module's error on the
  episode's window of local time is below threshold. C2 is gated exactly like C1 only
  with ``HPC.clusterers = "state"`` (one clusterer per local time step, shared by all
  contexts); with the default ``"context_state"`` a module has clusters only for the
  (context, state) pairs visited while it adapted, so C2 stays unfamiliar and S-A is
  learned a second time from C2. The freeze rule bounds the mean error over a
  context's states, not each window's, so some windows may stay ungated;
- the non-stationary S-D never reaches the freeze threshold; replayed as one fixed
  walk (``nonstationary = False``) it is stored like a learnable source;
- with LC lesioned to random switching, engage/disengage is a fair coin, the next
  context is uniform over the others, and neither depends on the PFC's values.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.learn.incsfa import IncSFA
from neurocur.regions.lc import EpsilonGreedyLC
from neurocur.regions.pfc import DISENGAGE, ENGAGE

CIRCUITS = Path(__file__).resolve().parents[2] / "neurocur" / "circuits"
THRESHOLD = 0.3
BOREDOM = -100.0
EPOCH = 1000  # local time steps of a built-in source


class ScriptedLC(EpsilonGreedyLC):
    """LC on a fixed schedule: the contexts of ``prelude`` first, then stay in ``home``
    until a module is stored, then cycle through ``tour``. Records epsilon 0."""

    def __init__(self, name="LC", *, prelude=(), home=0, tour=(0,), **params):
        super().__init__(name, **params)
        self.prelude, self.home, self.tour = tuple(prelude), home, tuple(tour)

    def reset(self, rng) -> None:
        super().reset(rng)
        self.n_decisions = self.n_stored = self.n_toured = 0

    def step(self, context, q, module_learned):
        self.n_stored += bool(module_learned)
        if self.n_decisions < len(self.prelude):
            nxt = self.prelude[self.n_decisions]
        elif self.n_stored == 0:
            nxt = self.home
        else:
            nxt = self.tour[self.n_toured % len(self.tour)]
            self.n_toured += 1
        self.n_decisions += 1
        action = ENGAGE if nxt == context else DISENGAGE
        self._rec = (action, nxt, 0.0, float(action), 0.0)
        return action, nxt, float(action)


def scripted(world, seed, *, lc, **overrides):
    """The CD-MISFA circuit with a scripted LC, starting in context 0."""
    circuit = Circuit.from_toml(CIRCUITS / "cd_misfa.toml", overrides={"sensory.initial_context": 0, **overrides})
    return circuit.replace("LC", lc).build(world, seed=seed)


def run_until_stored(sim, n_modules: int, max_frames: int):
    """Run episode by episode until the library holds ``n_modules`` modules."""
    while len(sim.regions["EC"].library) < n_modules and sim.n_frames < max_frames:
        sim.run(1)
    assert len(sim.regions["EC"].library) == n_modules, f"no module {n_modules} within {max_frames} frames"
    return sim


# ---------------------------------------------------------------------------- S-A gating

SA_WORLD = dict(contexts=["S-A", "S-A", "S-D"], clock_offsets=[0, 500, 0])  # C2 half an epoch out of phase
WINDOWS = EPOCH // 100  # a visit covers one of ten fixed 100-step windows of the local clock


def frozen_window_errors(sim, world, module=0):
    """Mean eq-10 error of a frozen module against its own clusters on each window of C1's frames."""
    hpc, ec = sim.regions["HPC"], sim.regions["EC"]
    err, known = hpc.library[module].error(np.arange(EPOCH), ec.library[module].transform(world.context_frames(0)))
    assert known.all()
    return err.reshape(WINDOWS, -1).mean(axis=1)


def with_windows(episodes, offsets=SA_WORLD["clock_offsets"]):
    """Episodes with the local window each showed (each visit advances its context's clock by one window)."""
    visit = episodes.groupby("context").cumcount()
    start = np.asarray(offsets)[episodes["context"]] // 100
    return episodes.assign(window=(start + visit) % WINDOWS)


def check_gating(episodes):
    """Familiar exactly when the smallest frozen error is below threshold; then DA is boredom."""
    assert (episodes["familiar"] == (episodes["min_frozen_error"] < THRESHOLD)).all()
    assert (episodes["da"] == BOREDOM).eq(episodes["familiar"]).all()
    assert (episodes["gating_module"] >= 0).eq(episodes["familiar"]).all()


#: The cause is in the learner (CCIPCA, Algorithm 2), not in HPC: C1's frames are rank 2, and the
#: first two CCIPCA directions, whose eigenvalues are nearly equal (2.358, 2.339), drift out of
#: orthogonality (cosine -0.054); deflating by non-orthogonal directions leaves a residual inside
#: the data, so the third component converges onto a copy of the first (cosine 0.995) with
#: eigenvalue sin^2 x lambda_1 = 0.0026 lambda_1, above eig_cutoff = 1e-3, and is active. The
#: whitening is then invalid (whitened variance 382 instead of 1, so gamma = 4 no longer exceeds
#: lambda_1 of the derivative and both CIMCA vectors coincide); the features jump by ~30 between
#: epochs and the per-visit drift happens to be small for one epoch. The same seed under the
#: synthetic experiment's reading (converged rule, min_spread) stores the same kind of module
#: (|corr| with the source 0.38). Orthonormalising the CCIPCA directions (Gram-Schmidt) fixes
#: every seed 0-15 of this test in a trial; the learner is not HPC's to change.
@pytest.mark.parametrize("seed", [2, 3, 10])
def test_module_on_sa_gates_c1_and_c2_alike_with_shared_state_clusterers(seed):
    """clusterers = "state": the module frozen in C1 gates C2 exactly where it gates C1.

    Familiarity is decided per episode, i.e. per window. The freeze rule bounds the
    *mean* of the stored errors over the context's states, not each window's error, so
    a window whose clusters are older than the others' may stay above threshold.
    Shared clusterers also mix sources: on other seeds the S-A module gates an S-D window.
    """
    world = SyntheticWorld(**SA_WORLD)
    sim = scripted(world, seed, lc=ScriptedLC(home=0, tour=(0, 1, 2)), **{"HPC.clusterers": "state"})
    run_until_stored(sim, 1, 60 * EPOCH)
    stored_at = sim.n_episodes - 1  # noqa: F841 (read by the query below)
    windows = frozen_window_errors(sim, world)
    sim.run(3 * WINDOWS * world.visit_length)  # every window of C1 and C2 once
    assert sim.products()["modules"]["context"].tolist() == [0]  # one module, learned in C1
    assert windows.mean() < THRESHOLD

    after = with_windows(sim.episodes()).query("episode > @stored_at")
    check_gating(after)
    c1, c2 = (after[after["context"] == c].set_index("window").sort_index() for c in (0, 1))
    assert list(c1.index) == list(c2.index) == list(range(WINDOWS))
    # C1's familiarity per window is the frozen module's error on that window ...
    np.testing.assert_allclose(c1["min_frozen_error"], windows, rtol=1e-9, atol=1e-12)
    assert (c1.loc[c1["familiar"], "gating_module"] == 0).all()
    # ... and C2 shows C1's frames at the same states, seen by the same clusterers: same errors, same gating
    np.testing.assert_allclose(c2["min_frozen_error"], c1["min_frozen_error"], rtol=1e-9, atol=1e-12)
    # gated episodes train nothing: the fresh adaptive module has seen only the unfamiliar ones
    n_unfamiliar = int((~after["familiar"]).sum())
    assert sim.regions["EC"].adaptive.n_samples_seen_ == n_unfamiliar * world.visit_length


@pytest.mark.parametrize("every, spurious", [(0, True), (100, False)])
def test_near_equal_eigenvalues_need_orthonormal_ccipca_directions(every, spurious):
    """Why the module of seed 10 was stored wrong under Algorithm 2 as published.

    C1's frames on seed 10 (S-A: two source dimensions of nearly equal variance, rank 2)
    replayed for the 173 episodes the module learned from: without re-orthonormalising
    (``every = 0``), the first two CCIPCA directions lose orthogonality and the third
    converges onto a copy of one of them inside the data, with an eigenvalue above the
    cut-off; the whitening is then invalid (whitened variance far from 1). Kept
    orthonormal every 100 samples (the EC default), two components are active and the
    whitened frames have unit covariance.
    """
    world = SyntheticWorld(**SA_WORLD)
    scripted(world, 10, lc=ScriptedLC(home=0))  # builds the circuit, which resets the world with seed 10
    frames = np.tile(world.context_frames(0), (18, 1))[:173 * world.visit_length]
    model = IncSFA(2, 3, amnesic=2.0, mean_rate="amnesic", derivative="current", orthonormalize=every,
                   mca_rates="equal", gamma=4.0, random_state=0)  # EC's reproduction choices, pinned
    for start in range(0, len(frames), world.visit_length):
        model.partial_fit(frames[start:start + world.visit_length])
    active = model._mask
    z = (frames[:EPOCH] - model.mean_) @ (model._dirs[active].T / np.sqrt(model._lam[active]))
    off_identity = np.abs(np.cov(z.T) - np.eye(int(active.sum()))).max()
    if spurious:
        assert model.n_active_ == 3 and off_identity > 10
    else:
        assert model.n_active_ == 2 and off_identity < 0.1  # the amnesic eigenvalue estimates are within a few %
        np.testing.assert_allclose(model._dirs[active] @ model._dirs[active].T, np.eye(2), atol=1e-3)


@pytest.mark.parametrize("seed", [0, 3])
def test_context_state_clusterers_leave_c2_unfamiliar_and_sa_is_learned_twice(seed):
    """clusterers = "context_state" (the default): a module has clusters only for the
    (context, state) pairs visited while it adapted. C2, visited for three early
    episodes, keeps stale clusters in three windows and none in the other seven: no C2
    episode is gated by the S-A module, and a second S-A module is learned from C2's frames
    (and C1's windows that the first leaves ungated; it may be stored on a visit of either,
    since C1's gated windows no longer block the freeze), which then gates C2."""
    world = SyntheticWorld(**SA_WORLD)
    lc = ScriptedLC(prelude=(1, 1, 1), home=0, tour=(0, 1))
    sim = scripted(world, seed, lc=lc, **{"HPC.clusterers": "context_state"})
    run_until_stored(sim, 1, 60 * EPOCH)
    first = sim.n_episodes - 1  # noqa: F841 (read by the queries below)
    run_until_stored(sim, 2, sim.n_frames + 60 * EPOCH)
    second = sim.n_episodes - 1  # noqa: F841

    assert sim.products()["modules"]["context"].tolist() in ([0, 0], [0, 1])  # S-A from C1, then S-A again
    windows = frozen_window_errors(sim, world)
    between = with_windows(sim.episodes()).query("@first < episode < @second")
    check_gating(between)
    c1, c2 = between[between["context"] == 0], between[between["context"] == 1]
    np.testing.assert_allclose(c1["min_frozen_error"], windows[c1["window"]], rtol=1e-9, atol=1e-12)
    assert not c2["familiar"].any()
    seen = c2["min_frozen_error"].notna()  # the three windows of the prelude
    assert 0 < seen.sum() < len(c2)
    assert (c2.loc[seen, "min_frozen_error"] > THRESHOLD).all()  # stale clusters
    # afterwards C2 is gated by its own module
    after = sim.run(20 * world.visit_length).episodes().query("episode > @second")
    check_gating(after)
    c2 = after[after["context"] == 1]
    assert c2["familiar"].any() and (c2.loc[c2["familiar"], "gating_module"] == 1).all()


# ---------------------------------------------------------------------------- S-D


@pytest.mark.parametrize("seed", [0, 1])
def test_nonstationary_sd_error_stays_above_threshold(seed):
    """S-D is redrawn at every wrap of its clock: 40 epochs of it, nothing is stored and,
    once every state has an error, the context error (eq 11 / M) stays above threshold."""
    world = SyntheticWorld(["S-D", "S-A"])
    sim = scripted(world, seed, lc=ScriptedLC(home=0)).run(40 * EPOCH)
    episodes = sim.episodes()
    assert (episodes["context"] == 0).all()
    assert sim.products()["modules"].empty and not episodes["module_learned"].any()
    full = episodes[episodes["episode"] >= EPOCH // world.visit_length]  # after the first epoch
    assert full["error"].notna().all()
    assert full["error"].min() > THRESHOLD


def test_stationary_sd_is_stored_like_a_learnable_source():
    """nonstationary = False replays one random walk: the per-state error then measures only
    how far the features move between epochs, and the module is stored within a few epochs."""
    world = SyntheticWorld(["S-D", "S-A"], nonstationary=False)
    sim = scripted(world, 0, lc=ScriptedLC(home=0))
    run_until_stored(sim, 1, 10 * EPOCH)
    assert sim.products()["modules"]["context"].tolist() == [0]


# ---------------------------------------------------------------------------- random LC


def test_random_switching_is_uniform():
    """lesion_lc_random.toml: epsilon = 1 throughout; engage with p = 1/2; disengage goes
    uniformly to one of the other four contexts; actions ignore the PFC's Q values."""
    world = SyntheticWorld(visit_length=10)  # short episodes: many decisions
    sim = Circuit.from_toml(CIRCUITS / "lesion_lc_random.toml").build(world, seed=2013).run(40_000)
    e = sim.episodes()
    n = len(e)
    assert n == 4000 and (e["epsilon"] == 1.0).all()
    engage = e["action"] == "engage"
    assert stats.binomtest(int(engage.sum()), n, 0.5).pvalue > 1e-3
    assert (e.loc[engage, "next_context"] == e.loc[engage, "context"]).all()
    moves = e[~engage]
    table = pd.crosstab(moves["context"], moves["next_context"]).reindex(index=range(5), columns=range(5), fill_value=0)
    counts = table.to_numpy()
    off = ~np.eye(5, dtype=bool)
    assert (counts[~off] == 0).all()
    expected = np.broadcast_to(counts.sum(axis=1, keepdims=True) / 4.0, counts.shape)[off]
    # 20 cells, 5 row totals fixed: 15 degrees of freedom
    assert stats.chisquare(counts[off], expected, ddof=4).pvalue > 1e-3
    prefer_engage = e["q_engage"] > e["q_disengage"]
    assert prefer_engage.any() and (~prefer_engage).any()
    assert stats.chi2_contingency(pd.crosstab(prefer_engage, engage).to_numpy()).pvalue > 1e-3
