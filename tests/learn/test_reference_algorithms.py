"""One block of the learners against a plain NumPy transcription of the paper's algorithms.

The compiled learners (``neurocur.learn._kernels``, ``_roc_kernels``) are fast and
restructured (CCIPCA keeps each component as a unit direction and a length, the whitened
derivative is projected inside the CCIPCA passes, residual norms are computed in closed
form). Each test here warms a learner up, copies its own state, runs one more block of
``partial_fit`` and replays the same block, sample by sample, through a transcription
written from the paper's equations; the two must agree to ~1e-8.

Transcribed (Luciw et al. 2013; Algorithms 1 and 2 as reconstructed in the paper folder's
NOTES.md):

- Algorithm 2 (CCIPCA, Weng et al. 2003): η(t) = (1 + μ(t))/t, capped at 1; the mean
  ū ← (1 − ρ)ū + ρx with ρ = η (``mean_rate="amnesic"``) or 1/t (``"cumulative"``, the
  learners' default) and u = x − ū; for i = 1..K: v_i ← (1 − η)v_i + η (u·v̂_i) u, then
  u ← u − (u·v̂_i) v̂_i with the *updated* v̂_i; λ_i = ||v_i||. A component of length 0
  keeps its direction (the learner's documented initialisation).
- The learner's documented choices: components below ``eig_cutoff`` × the largest
  eigenvalue, or outside ``var_fraction``, are inactive; the derivative is
  ż = Sᵀ(x(t) − x(t−1)) with the whitening S = [v̂_i / √λ_i] *after* this sample's CCIPCA
  update (``derivative="current"``), or ż = z(t) − z(t−1) with z(t) = S(t)ᵀ(x(t) − ū(t))
  (``"successive"``, the default; a sample with no active component leaves no z(t−1)),
  ż = 0 on inactive components; no derivative across blocks unless ``continues``.
- Eq 8 / eqs 16–17 (CIMCA): for i = 1..J, with the already updated w_j (j < i),
  w_i ← (1 − η_i)w_i − η_i[(ż·w_i) ż + γ Σ_{j<i} (w_j·w_i) w_j] (η_i = η for every vector in
  the paper; the learner's default slows them all, ``mca_rates``), restricted to the active
  coordinates and normalised; γ given, 1.2 · 0.2/η (``"reference"``), or ``AUTO_GAMMA_FACTOR`` ×
  λ̂_1(ż) from a one-component CCIPCA on ż with the same amnesic rate.
- Algorithm 3 (ROC-Amnesic) with the Gaussian RESPONSE of ``neurocur.learn.roc``.
"""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.learn.ccipca import REFERENCE_SCHEDULE, AmnesicSchedule
from neurocur.learn.incsfa import IncSFA
from neurocur.learn.mca import AUTO_GAMMA_FACTOR
from neurocur.learn.roc import ROCBank

RTOL = 1e-8

# ------------------------------------------------------------------ Algorithms 1 and 2


def mu(t, amnesic):
    """μ(t) of Algorithm 2: a constant l, or the (t1, t2, c, r) schedule ("reference": (20, 200, 3, 2000))."""
    if amnesic == "reference":
        amnesic = REFERENCE_SCHEDULE
    if not isinstance(amnesic, AmnesicSchedule):
        return amnesic
    s = amnesic
    if t <= s.t1:
        return 0.0
    if t <= s.t2:
        return s.c * (t - s.t1) / (s.t2 - s.t1)
    return s.c + (t - s.t2) / s.r


def rate(t, amnesic):
    return min(1.0, (1.0 + mu(t, amnesic)) / t)


def unit(v, fallback):
    n = np.linalg.norm(v)
    return v / n if n > 0 else fallback


def ccipca_sample(V, dirs, u, eta):
    """Algorithm 2 on one centred sample: ``V`` (K, D) holds v_i = λ_i v̂_i; returns the new V and v̂."""
    V, dirs, r = V.copy(), dirs.copy(), u.copy()
    for i in range(len(V)):
        v_hat = unit(V[i], dirs[i])
        V[i] = (1 - eta) * V[i] + eta * (r @ v_hat) * r
        dirs[i] = unit(V[i], dirs[i])
        r = r - (r @ dirs[i]) * dirs[i]
    return V, dirs


def active(lam, total, eig_cutoff, var_fraction):
    """The learner's active components: by descending λ, λ > 0 and ≥ cutoff × the largest,
    until the taken ones explain ``var_fraction`` of the total variance."""
    keep = np.zeros(len(lam), dtype=bool)
    explained = 0.0
    for i in np.argsort(-lam, kind="stable"):
        if var_fraction and explained >= var_fraction * total:
            break
        if lam[i] <= 0 or lam[i] < eig_cutoff * lam.max():
            break
        keep[i] = True
        explained += lam[i]
    return keep


def mca_rates(p, n):
    """η_i of each CIMCA vector: the paper's η for all (``mca_rates="equal"``), η / (1.5 (1 + 1.2 (i − 1)))
    for w_i (``"reference"``, the IncSFA author's code), or that for i ≥ 2 and η for w_1 (``"decreasing"``)."""
    eta = p["mca_rate"]
    if p["mca_rates"] == "equal":
        return [eta] * n
    slowed = [eta / (1.5 * (1 + 1.2 * i)) for i in range(n)]
    return slowed if p["mca_rates"] == "reference" else [eta] + slowed[1:]


def cimca_sample(W, zdot, rates, gamma, keep):
    """Eq 8 (eqs 16–17 for w_1): sequential, with the already updated w_j; restricted to
    the active coordinates, then unit length. ``rates``: η_i per vector."""
    W = W.copy()
    for i in range(len(W)):
        eta = rates[i]
        lateral = sum((W[j] @ W[i]) * W[j] for j in range(i))
        w = (1 - eta) * W[i] - eta * ((zdot @ W[i]) * zdot + gamma * lateral)
        kept = np.where(keep, w, 0.0)
        W[i] = kept / np.linalg.norm(kept) if np.linalg.norm(kept) > 0 else w / np.linalg.norm(w)
    return W


def incsfa_reference(state, X, p, continues=False):
    """Algorithm 1 over the rows of ``X`` from ``state``; returns the new state."""
    s = {k: np.copy(v) for k, v in state.items()}
    V = s["lam"][:, None] * s["dirs"]
    G = s["glam"][:, None] * s["gdir"]
    has_prev = continues
    for x in X:
        s["t"] += 1
        eta = rate(s["t"], p["amnesic"])
        mean_rate = 1 / s["t"] if p["mean_rate"] == "cumulative" else eta
        s["mean"] = (1 - mean_rate) * s["mean"] + mean_rate * x
        u = x - s["mean"]
        s["total"] = (1 - eta) * s["total"] + eta * (u @ u)
        V, s["dirs"] = ccipca_sample(V, s["dirs"], u, eta)
        lam = np.linalg.norm(V, axis=1)
        keep = active(lam, s["total"], p["eig_cutoff"], p["var_fraction"])
        S = np.where(keep, s["dirs"].T / np.sqrt(np.where(keep, lam, 1.0)), 0.0)  # current S, (D, K)
        if p["derivative"] == "successive":
            z = S.T @ u
            zdot, s["zprev"] = z - s["zprev"], z
        else:
            zdot = S.T @ (x - s["prev"])
        if has_prev:
            gamma = p["gamma"]
            if gamma == "reference":
                gamma = 1.2 * 0.2 / p["mca_rate"]
            if gamma == "auto":
                G, s["gdir"] = ccipca_sample(G, s["gdir"], zdot, eta)
                gamma = AUTO_GAMMA_FACTOR * np.linalg.norm(G[0])
            s["W"] = cimca_sample(s["W"], zdot, mca_rates(p, len(s["W"])), gamma, keep)
        s["prev"] = x.copy()
        has_prev = bool(keep.any()) if p["derivative"] == "successive" else True
    s["lam"], s["glam"] = np.linalg.norm(V, axis=1), np.linalg.norm(G, axis=1)
    s["keep"] = active(s["lam"], s["total"], p["eig_cutoff"], p["var_fraction"])
    return s


def incsfa_state(model):
    """The learner's own state, copied."""
    return {
        "t": model.n_samples_seen_, "total": model._total, "mean": model.mean_.copy(),
        "dirs": model._dirs.copy(), "lam": model._lam.copy(), "W": model._W.copy(),
        "gdir": model._gdir.copy(), "glam": model._glam.copy(), "prev": model._prev.copy(),
        "zprev": model._zprev.copy(),
    }


def projection(s):
    keep = s["keep"]
    return (s["dirs"][keep].T / np.sqrt(s["lam"][keep])) @ s["W"][:, keep].T


def assert_same_state(model, ref):
    top = ref["lam"].max()
    keep = ref["keep"]
    assert model.n_samples_seen_ == ref["t"]
    np.testing.assert_array_equal(model._mask, keep)
    np.testing.assert_allclose(model.mean_, ref["mean"], rtol=RTOL, atol=RTOL)
    np.testing.assert_allclose(model._total, ref["total"], rtol=RTOL)
    np.testing.assert_allclose(model._lam, ref["lam"], rtol=RTOL, atol=RTOL * top)
    # an inactive component carries round-off only (its direction is then arbitrary)
    np.testing.assert_allclose(model._dirs[keep], ref["dirs"][keep], atol=RTOL)
    np.testing.assert_allclose(model._W, ref["W"], atol=RTOL)
    np.testing.assert_allclose(model._glam, ref["glam"], rtol=RTOL, atol=RTOL)
    np.testing.assert_allclose(model.projection_, projection(ref), rtol=RTOL, atol=RTOL * np.abs(projection(ref)).max())


@pytest.fixture(scope="module")
def sb_frames():
    """1000 frames of the synthetic world's S-B context (400 pixels, rank 3: K = 3 has an
    inactive component, as in the circuit)."""
    world = SyntheticWorld(["S-B", "S-A"])
    world.reset(seed=5)
    return world.context_frames(0)


@pytest.fixture(scope="module")
def mixture():
    """1000 samples of a 12-d full-rank mixture of four sinusoids and noise."""
    rng = np.random.default_rng(3)
    t = np.arange(1000)[:, None]
    src = np.sin(2 * np.pi * t * np.array([2, 9, 31, 70]) / 1000 + rng.uniform(0, 6, 4))
    return src @ rng.standard_normal((4, 12)) + 0.05 * rng.standard_normal((1000, 12))


#: the EC region's pinned choices (neurocur.regions.ec.ECParams), which differ from the learner's defaults
CIRCUIT = {"amnesic": 2.0, "mean_rate": "amnesic", "derivative": "current", "mca_rates": "equal", "gamma": 4.0}

CASES = {
    "learner default": ("sb_frames", {}),
    "circuit (EC's choices)": ("sb_frames", CIRCUIT),
    "current derivative, amnesic mean": ("sb_frames", {"derivative": "current", "mean_rate": "amnesic"}),
    "gamma auto": ("sb_frames", {"gamma": "auto"}),
    "full rank, K = 6, J = 3": ("mixture", {"n_components": 3, "n_pca": 6}),
    "full rank, equal rates": ("mixture", {"n_components": 3, "n_pca": 6, "mca_rates": "equal"}),
    "var_fraction": ("mixture", {"n_components": 2, "n_pca": 6, "var_fraction": 0.9}),
    "amnesic schedule": ("mixture", {"n_components": 2, "n_pca": 4, "amnesic": AmnesicSchedule(5, 50, 2.0, 500)}),
}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("warm_up", [300, 900])
def test_incsfa_block_equals_algorithms_1_and_2(request, case, warm_up):
    """From the learner's own state after ``warm_up`` samples (the whitening still moving
    at 300), one 100-sample episode of ``partial_fit`` equals the transcription."""
    data, params = CASES[case]
    X = request.getfixturevalue(data)
    model = IncSFA(**params, random_state=11)
    for start in range(0, warm_up, 100):
        model.partial_fit(X[start : start + 100])
    state, block = incsfa_state(model), X[warm_up : warm_up + 100]
    ref = incsfa_reference(state, block, model.get_params())
    model.partial_fit(block)
    assert_same_state(model, ref)
    assert model._mask.sum() >= 2  # the block exercised the whitening and CIMCA


def test_incsfa_continued_block_differences_across_the_call(sb_frames):
    """``continues=True``: the block's first row is differenced against the previous call's last."""
    model = IncSFA(random_state=4)
    for start in range(0, 500, 100):
        model.partial_fit(sb_frames[start : start + 100])
    state, block = incsfa_state(model), sb_frames[500:600]
    ref = incsfa_reference(state, block, model.get_params(), continues=True)
    cut = incsfa_reference(state, block, model.get_params(), continues=False)
    model.partial_fit(block, continues=True)
    assert_same_state(model, ref)
    assert np.abs(ref["W"] - cut["W"]).max() > 30 * RTOL  # the one extra derivative is visible


def test_incsfa_first_block_from_the_initial_state(sb_frames):
    """The very first block, from the learner's random start (eigenvalues 0, the first
    ⌊1 + l⌋ samples only set the mean)."""
    model = IncSFA(random_state=8)
    model.partial_fit(sb_frames[:100])
    start = IncSFA(random_state=8)
    start._start(sb_frames.shape[1])
    ref = incsfa_reference(incsfa_state(start), sb_frames[:100], model.get_params())
    assert_same_state(model, ref)


# ------------------------------------------------------------------ Algorithm 3


def response(y, c, width):
    return np.exp(-np.sum((y - c) ** 2) / (2 * width**2))


def roc_reference(C, a, n, latest, states, Y, xi, phi, width):
    """Algorithm 3 per row: lists of centres and weights per state, in slot order."""
    C, a, n, latest = C.copy(), a.copy(), n.copy(), latest.copy()
    for s, y in zip(states, Y):
        if n[s] < xi:  # lines 2-3
            C[s, n[s]], a[s, n[s]], latest[s] = y, 0.0, n[s]
            n[s] += 1
            continue
        win = int(np.argmax([response(y, c, width) for c in C[s]]))  # line 5, ties to the lowest slot
        C[s, win] = C[s, win] + (y - C[s, win]) / (a[s, win] + 1)  # line 6
        a[s, win] += response(y, C[s, win], width)  # line 7
        pairs = [(g, d) for g in range(xi) for d in range(g + 1, xi)]
        g, d = pairs[int(np.argmax([response(C[s, g], C[s, d], width) for g, d in pairs]))]  # line 8
        total = a[s, g] + a[s, d]
        C[s, g] = (C[s, g] * a[s, g] + C[s, d] * a[s, d]) / total if total > 0 else (C[s, g] + C[s, d]) / 2  # 9
        a[s, g] = total  # line 10
        C[s, d], a[s, d], latest[s] = y, 0.0, d  # lines 11-12
        a[s] *= 1 - phi  # lines 13-15
    return C, a, n, latest


@pytest.mark.parametrize("xi", [2, 3])
def test_roc_block_equals_algorithm_3(xi):
    """From a warmed-up bank's own arrays, one block of ``partial_fit`` equals Algorithm 3;
    the block reaches states with no cluster yet, with fewer than ξ and with ξ clusters."""
    rng = np.random.default_rng(xi)
    n_states, phi, width = 12, 0.05, 0.8
    bank = ROCBank(n_states, 2, max_clusters=xi, amnesic=phi, width=width)
    centres = rng.normal(0, 2, size=(n_states, 2, 2))
    warm = rng.integers(0, 8, size=300)  # states 8-11 stay empty until the block
    pick = rng.integers(0, 2, size=300)
    bank.partial_fit(warm, centres[warm, pick] + 0.4 * rng.normal(size=(300, 2)))
    states = rng.integers(0, n_states, size=400)
    Y = centres[states, rng.integers(0, 2, size=400)] + 0.4 * rng.normal(size=(400, 2))
    ref = roc_reference(bank.centers_, bank.weights_, bank.n_clusters_, bank.latest_, states, Y, xi, phi, width)
    bank.partial_fit(states, Y)
    C, a, n, latest = ref
    np.testing.assert_array_equal(bank.n_clusters_, n)
    np.testing.assert_array_equal(bank.latest_, latest)
    np.testing.assert_allclose(bank.centers_, C, rtol=RTOL, atol=RTOL)
    np.testing.assert_allclose(bank.weights_, a, rtol=RTOL, atol=RTOL)
    assert (a > 0.5).any() and (n == xi).all()  # weights grew, every state filled up
