"""Compiled per-sample loops of the incremental slow-feature learners.

Everything here is sequential (each sample's update depends on the previous one), so
it runs under numba in float64 without fast-math. The Python classes in
``ccipca.py``, ``mca.py`` and ``incsfa.py`` own validation and state; these functions
only update the arrays they are given, in place.

State conventions
-----------------
CCIPCA (Algorithm 2) stores each component as a unit direction ``dirs[i]`` and its
length ``lam[i]`` (the eigenvalue estimate), i.e. ``v_i = lam[i] * dirs[i]``. Keeping
the two apart means a component whose length is still zero (nothing learned yet, or a
direction outside the data's rank) never causes a division by zero: its direction is
kept and its eigenvalue is 0. The amnesic schedule (t1, t2, c, r) covers both of the
paper's forms: the constant amnesic parameter ``l`` is ``(0, 0, l, inf)``.

The opt-in float32 fast path, compiled from these same functions, is in ``_kernels_fast``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._lanes import dot4_lanes


@njit(cache=True, fastmath=False)
def amnesic_rate(t, t1, t2, c, r):
    """Learning rate η(t) = (1 + μ(t)) / t of the t-th sample (t ≥ 1), capped at 1.

    μ(t) is 0 for t ≤ t1, c (t − t1)/(t2 − t1) for t1 < t ≤ t2 and c + (t − t2)/r
    after (Algorithm 2). The cap keeps the weight of the old estimate, 1 − η, from
    going negative for the first few samples when μ > 0 from the start.
    """
    if t <= t1:
        mu = 0.0
    elif t <= t2:
        mu = c * (t - t1) / (t2 - t1)
    else:
        mu = c + (t - t2) / r
    eta = (1.0 + mu) / t
    return eta if eta < 1.0 else 1.0


@njit(cache=True, fastmath=False)
def dot2(x, y, z):
    """(x·y, x·z) in one pass, with four partial sums each (independent add chains)."""
    n = x.shape[0]
    s0 = s1 = s2 = s3 = 0.0
    t0 = t1 = t2 = t3 = 0.0
    m = n - n % 4
    for d in range(0, m, 4):
        s0 += x[d] * y[d]
        s1 += x[d + 1] * y[d + 1]
        s2 += x[d + 2] * y[d + 2]
        s3 += x[d + 3] * y[d + 3]
        t0 += x[d] * z[d]
        t1 += x[d + 1] * z[d + 1]
        t2 += x[d + 2] * z[d + 2]
        t3 += x[d + 3] * z[d + 3]
    for d in range(m, n):
        s0 += x[d] * y[d]
        t0 += x[d] * z[d]
    return (s0 + s1) + (s2 + s3), (t0 + t1) + (t2 + t3)


@njit(cache=True, fastmath=False)
def dot4(v, r, x):
    """(v·r, r·r, v·x, r·x) in one pass, with two partial sums each: one over the even and
    one over the odd indices, in order (an odd last element joins the even one), added
    at the end. The two partial sums are the lanes of one SIMD vector
    (``_lanes.dot4_lanes``), which keeps this order exactly."""
    return dot4_lanes(v, r, x)


@njit(cache=True, fastmath=False)
def sums(row, res, dx, project):
    """(row·r, r·r, row·dx, r·dx) with ``project``, else (row·r, r·r, 0, 0): one pass."""
    if project:
        return dot4(row, res, dx)
    p, rr = dot2(res, row, res)
    return p, rr, 0.0, 0.0


@njit(cache=True, fastmath=False)
def update_sums(row, res, a, b, inv, c, nxt, dx, project, more):
    """Set row ← (a row + b r)/‖·‖ (``inv`` = 1/‖·‖), deflate r ← r − c row; then, if
    ``more``, return ``sums(nxt, r, dx, project)`` of the next component (else zeros)."""
    for d in range(res.shape[0]):
        v = (a * row[d] + b * res[d]) * inv
        row[d] = v
        res[d] -= c * v
    if more:
        return sums(nxt, res, dx, project)
    return 0.0, 0.0, 0.0, 0.0


@njit(cache=True, fastmath=False)
def ccipca_step(u, dirs, lam, eta, dx, proj):
    """One CCIPCA update (Algorithm 2) of all components on the centred sample ``u``.

    For i = 1..K: v_i ← (1 − η) v_i + η (r·v̂_i) r, then deflate the residual
    r ← r − (r·v̂_i) v̂_i with the updated v̂_i; r starts as ``u`` and is deflated in
    place (``u`` is overwritten). With v_i = λ_i v̂_i, a = (1 − η) λ_i and
    b = η (r·v̂_i), the new length is ||a v̂_i + b r||² = a² + 2ab (r·v̂_i) + b² ||r||²,
    a sum of non-negative terms; r·v̂_i and ||r||² come from one pass over the inputs
    (``sums``) and the update is a second pass (``update_sums``, which the fast path
    fuses with the next component's sums). (||r||² is not carried through the
    deflations as ||r||² − (r·v̂_i)²: that cancels once the residual is at round-off
    level, as for rank-deficient input, and an underestimate would inflate v̂_i.)

    If ``dx`` is non-empty, ``proj[i]`` receives v̂_i·dx for the updated v̂_i (IncSFA's
    unscaled whitened derivative) from the same passes:
    v̂_i'·dx = (a v̂_i·dx + b r·dx) / λ_i'. Returns ||u||².
    """
    K = dirs.shape[0]
    project = dx.shape[0] > 0
    res = u
    p, rr, q, rdx = sums(dirs[0], res, dx, project)
    uu = rr
    for i in range(K):
        row = dirs[i]
        more = i + 1 < K
        nxt = dirs[i + 1] if more else row
        a = (1.0 - eta) * lam[i]
        b = eta * p
        norm2 = a * a + 2.0 * a * b * p + b * b * rr
        if norm2 <= 0.0:
            lam[i] = 0.0
            if project:
                proj[i] = 0.0
            if more:
                p, rr, q, rdx = sums(nxt, res, dx, project)
            continue
        new = np.sqrt(norm2)
        inv = 1.0 / new
        c = (a * p + b * rr) * inv  # r · v̂_new
        lam[i] = new
        if project:
            proj[i] = (a * q + b * rdx) * inv
        p, rr, q, rdx = update_sums(row, res, a, b, inv, c, nxt, dx, project, more)
    return uu


@njit(cache=True, fastmath=False)
def orthonormalize(dirs):
    """Modified Gram–Schmidt on the rows of ``dirs``, in order: v̂_1 keeps its direction,
    each later v̂_i loses its parts along v̂_1..v̂_{i−1} and is renormalised.

    Algorithm 2's deflation keeps the directions orthogonal only approximately: the old
    part (1 − η) v_i of an update is not deflated by the *updated* v̂_j (j < i). When two
    eigenvalues are nearly equal the errors accumulate, and a later component can
    converge onto a copy of an earlier one. A row with (almost) nothing left after the
    projections, a component inside the span of the earlier ones, is left unchanged.
    """
    K, D = dirs.shape
    keep = np.empty(D)
    for i in range(K):
        for d in range(D):
            keep[d] = dirs[i, d]
        for j in range(i):
            c = 0.0
            for d in range(D):
                c += dirs[i, d] * dirs[j, d]
            for d in range(D):
                dirs[i, d] -= c * dirs[j, d]
        n2 = 0.0
        for d in range(D):
            n2 += dirs[i, d] * dirs[i, d]
        if n2 > 1e-24:
            inv = 1.0 / np.sqrt(n2)
            for d in range(D):
                dirs[i, d] *= inv
        else:
            for d in range(D):
                dirs[i, d] = keep[d]


@njit(cache=True, fastmath=False)
def active_mask(lam, total_var, eig_cutoff, var_fraction, mask):
    """Mark the components the whitening may use (``mask[i] = True``); return their count.

    Components are taken in descending order of eigenvalue. Taking stops at a component
    whose eigenvalue is zero or below ``eig_cutoff`` times the largest, or once the
    components taken explain at least ``var_fraction`` of ``total_var``
    (``var_fraction <= 0`` disables that rule).
    """
    K = lam.shape[0]
    top = 0.0
    for i in range(K):
        mask[i] = False
        if lam[i] > top:
            top = lam[i]
    n = 0
    explained = 0.0
    while n < K:
        if var_fraction > 0.0 and explained >= var_fraction * total_var:
            break
        best = -1
        best_lam = 0.0
        for i in range(K):
            if not mask[i] and lam[i] > best_lam:
                best = i
                best_lam = lam[i]
        if best < 0 or best_lam < eig_cutoff * top:
            break
        mask[best] = True
        explained += best_lam
        n += 1
    return n


@njit(cache=True, fastmath=False)
def cimca_step(zdot, W, rates, gamma, mask, coup, new):
    """One CIMCA update (paper eqs 8, 16, 17) of the J minor-component vectors ``W``.

    Sequentially for i = 1..J, with the already updated w_j (j < i) and the component's
    rate η_i = ``rates[i]`` (:func:`neurocur.learn.mca.component_rates`):
    w_i ← (1 − η_i) w_i − η_i [(ż·w_i) ż + γ Σ_{j<i} (w_j·w_i) w_j], then w_i is restricted
    to the coordinates where ``mask`` is True and normalised to unit length (if the
    restriction leaves nothing, the unrestricted update is normalised instead).
    ``coup`` (J,) and ``new`` (K,) are work arrays.
    """
    J, K = W.shape
    for i in range(J):
        rate = rates[i]
        p = 0.0
        for k in range(K):
            p += zdot[k] * W[i, k]
        for j in range(i):
            c = 0.0
            for k in range(K):
                c += W[j, k] * W[i, k]
            coup[j] = gamma * c
        full2 = 0.0
        kept2 = 0.0
        for k in range(K):
            lateral = 0.0
            for j in range(i):
                lateral += coup[j] * W[j, k]
            w = (1.0 - rate) * W[i, k] - rate * (p * zdot[k] + lateral)
            new[k] = w
            full2 += w * w
            if mask[k]:
                kept2 += w * w
        if kept2 > 0.0:
            inv = 1.0 / np.sqrt(kept2)
            for k in range(K):
                W[i, k] = new[k] * inv if mask[k] else 0.0
        elif full2 > 0.0:
            inv = 1.0 / np.sqrt(full2)
            for k in range(K):
                W[i, k] = new[k] * inv


@njit(cache=True, fastmath=False)
def ccipca_fit(X, t, mean, dirs, lam, total_var, t1, t2, c, r, cumulative_mean, ortho_every, u):
    """Run Algorithm 2 over the rows of ``X``; return the new (sample count, total variance).

    Per sample: t ← t + 1, η = amnesic_rate(t); if ``ortho_every > 0`` and t is a
    multiple of it, the directions are first re-orthonormalised (``orthonormalize``);
    the total variance (the trace of the covariance, for the variance-fraction rule) is
    tracked with the same η, and the mean with rate 1/t if ``cumulative_mean`` (the
    average of all samples) else with η; then ``ccipca_step`` runs on the centred sample.
    """
    T, D = X.shape
    none = np.empty(0)
    for s in range(T):
        t += 1
        if ortho_every > 0 and t % ortho_every == 0:
            orthonormalize(dirs)
        eta = amnesic_rate(t, t1, t2, c, r)
        rate = 1.0 / t if cumulative_mean else eta
        for d in range(D):
            m = mean[d] + rate * (X[s, d] - mean[d])
            mean[d] = m
            u[d] = X[s, d] - m
        uu = ccipca_step(u, dirs, lam, eta, none, none)
        total_var = (1.0 - eta) * total_var + eta * uu
    return t, total_var


@njit(cache=True, fastmath=False)
def cimca_fit(Z, W, rates, gamma, gamma_factor, gdir, glam, t, mask, coup, new, res):
    """Run CIMCA over the rows of ``Z``; return the new sample count.

    The largest eigenvalue λ̂_1 of the second moment of ``Z`` is always tracked, by a
    one-component CCIPCA with rate 1/t (``gdir`` (1, K), ``glam`` (1,)). If
    ``gamma_factor > 0`` the lateral weight is estimated online as
    γ = gamma_factor × λ̂_1; otherwise the given ``gamma`` is used.
    """
    T = Z.shape[0]
    none = np.empty(0)
    for s in range(T):
        t += 1
        z = Z[s]
        for k in range(z.shape[0]):
            res[k] = z[k]
        ccipca_step(res, gdir, glam, 1.0 / t, none, none)
        if gamma_factor > 0.0:
            gamma = gamma_factor * glam[0]
        cimca_step(z, W, rates, gamma, mask, coup, new)
    return t


@njit(cache=True, fastmath=False)
def incsfa_fit(
    X, t, total_var, has_prev, mean, dirs, lam, prev, zprev, W, gdir, glam,
    t1, t2, c, r, cumulative_mean, successive, ortho_every, eig_cutoff, var_fraction, rates, gamma, gamma_factor,
    mask, u, dx, zdot, gres, coup, new,
):
    """Run IncSFA (Algorithm 1) over one block of consecutive samples ``X``.

    Per sample x(t): re-orthonormalise the CCIPCA directions if ``ortho_every > 0``
    and t is a multiple of it (as in ``ccipca_fit``); update the mean (rate 1/t if
    ``cumulative_mean``, else the amnesic rate), the total variance and CCIPCA on x − ū
    with the amnesic rate; choose the active components (``active_mask``); then, if the
    previous sample of the same episode is known (``has_prev``), form the whitened
    derivative and update CIMCA on it. Without ``successive`` the derivative uses the
    current whitening matrix S for both samples, ż = S(t)ᵀ(x(t) − x(t−1)); with it, the
    difference of the whitened samples, ż = z(t) − z(t−1) with z(t) = S(t)ᵀ(x(t) − ū(t)),
    each whitened by the matrix and mean of its own time (the IncSFA author's code;
    z(t) is kept in ``zprev``, and a sample with no active component gives no z(t−1)).
    Inactive components have z = ż = 0 and are excluded from the CIMCA vectors.
    With ``gamma_factor > 0``, γ = gamma_factor × λ̂_1(ż) tracked online (one-component
    CCIPCA on ż with the same amnesic rate). The last sample is stored in ``prev``.
    Returns the new (sample count, total variance, number of active components, has_prev).
    """
    T, D = X.shape
    K = dirs.shape[0]
    n_active = 0
    none = np.empty(0, dx.dtype)
    for s in range(T):
        t += 1
        if ortho_every > 0 and t % ortho_every == 0:
            orthonormalize(dirs)
        eta = amnesic_rate(t, t1, t2, c, r)
        rate = 1.0 / t if cumulative_mean else eta
        for d in range(D):
            x = X[s, d]
            m = mean[d] + rate * (x - mean[d])
            mean[d] = m
            u[d] = x - m
            dx[d] = u[d] if successive else x - prev[d]
            prev[d] = x
        # with no previous sample and no z(t) to keep there is nothing to project: an empty dx skips it
        project = successive or has_prev
        uu = ccipca_step(u, dirs, lam, eta, dx if project else none, zdot)
        total_var = (1.0 - eta) * total_var + eta * uu
        n_active = active_mask(lam, total_var, eig_cutoff, var_fraction, mask)
        if project:
            for i in range(K):
                zdot[i] = zdot[i] / np.sqrt(lam[i]) if mask[i] else 0.0
        if successive:
            for i in range(K):
                z = zdot[i]
                zdot[i] = z - zprev[i]
                zprev[i] = z
        if has_prev:
            if gamma_factor > 0.0:
                for k in range(K):
                    gres[k] = zdot[k]
                ccipca_step(gres, gdir, glam, eta, none, none)
                gamma = gamma_factor * glam[0]
            cimca_step(zdot, W, rates, gamma, mask, coup, new)
        has_prev = n_active > 0 if successive else True
    return t, total_var, n_active, has_prev
