"""The learning-cost measure Ω of CIMCA (paper eqs 15 and 40).

Ω(x) = 1 − η(λ_{n−1} − λ_n) / (1 − η − η λ_n), where λ_n ≤ λ_{n−1} are the two
smallest eigenvalues of the second-moment matrix of the derivative of the whitened
signal. Ω is the per-step contraction factor S_{n−1} (eq 26) of the penultimate
coefficient of the MCA weight vector: lower Ω means faster learning, and white noise
(λ_{n−1} = λ_n) gives Ω = 1, never learned.
"""

from __future__ import annotations

import numpy as np

from ..config import param_specs
from ..config.checks import check_block, check_nonconstant
from .mca import MCA
from .sfa_batch import whiten_batch


def derivative_eigenvalues(X, *, rank_tol: float = 1e-10, starts=None) -> np.ndarray:
    """Ascending eigenvalues of ``<ż żᵀ>`` for the whitened signal ``z`` of ``X``.

    Parameters
    ----------
    X : array of shape (samples, features)
        The signal, rows in time (at least 3).
    rank_tol : float
        Directions whose variance is below ``rank_tol`` times the largest are dropped from the whitening.
    starts : sequence of int, optional
        Row indices where an independent episode begins inside ``X`` (the whitening is fitted to all
        rows together); no derivative spans one of them.

    Returns
    -------
    array
        The eigenvalues, ascending.
    """
    X = check_block(X, min_rows=3)
    check_nonconstant(X)
    Z, _, _ = whiten_batch(X, rank_tol)
    dZ = np.diff(Z, axis=0)
    if starts is not None:
        dZ = np.delete(dZ, _boundaries(starts, len(X)) - 1, axis=0)
    return np.linalg.eigvalsh(dZ.T @ dZ / len(dZ))


def _boundaries(starts, n_rows: int) -> np.ndarray:
    """The episode starts after row 0, checked: sorted, distinct ints in [0, n_rows), none within 2 of another."""
    arr = np.asarray(starts)
    if arr.ndim != 1 or arr.dtype.kind not in "iu":
        raise ValueError(f"starts must be a 1-d array of row indices (ints); got {starts!r}")
    edges = np.concatenate([[0], arr[arr > 0], [n_rows]])
    if arr.size and (arr.min() < 0 or arr.max() >= n_rows) or np.any(np.diff(edges) < 2):
        raise ValueError(f"starts must be increasing row indices in [0, {n_rows}) with episodes of at least 2 rows; "
                         f"got {starts!r}")
    return edges[1:-1]


def omega_from_eigenvalues(lam, eta: float) -> float:
    """Eq 40 from ascending derivative eigenvalues ``lam`` (needs at least two)."""
    lam = np.sort(np.asarray(lam, dtype=np.float64))
    if lam.size < 2:
        raise ValueError("Ω needs at least two whitened dimensions (λ_n and λ_{n-1})")
    lam_n, lam_n1 = lam[0], lam[1]
    return float(1.0 - eta * (lam_n1 - lam_n) / (1.0 - eta - eta * lam_n))


def omega(X, eta: float = 0.05, *, rank_tol: float = 1e-10, starts=None) -> float:
    """Ω of the signal ``X`` (rows are time) for MCA learning rate ``eta`` (eq 40).

    ``starts`` marks where independent episodes begin inside ``X`` (see
    :func:`derivative_eigenvalues`).

    The convergence conditions of eq 20 (η λ_1 < 0.5, 0 < η ≤ 0.5) must hold for Ω to
    be meaningful; a ``ValueError`` says so when they do not.
    """
    eta = param_specs(MCA)["learning_rate"].coerce(eta, source="omega", key="eta")  # MCA's η
    lam = derivative_eigenvalues(X, rank_tol=rank_tol, starts=starts)
    if eta * lam[-1] >= 0.5:
        raise ValueError(
            f"eta * lambda_1 = {eta * lam[-1]:.3g} must be < 0.5 for MCA to converge (eq 20); lower eta"
        )
    return omega_from_eigenvalues(lam, eta)
