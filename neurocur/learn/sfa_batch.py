"""Exact linear slow feature analysis, the batch reference (Wiskott & Sejnowski 2002).

The slow features solve the generalised eigenproblem ``A w = Δ B w`` with
``A = <ẋ ẋᵀ>`` (derivative covariance) and ``B = <x xᵀ>`` (input covariance), paper
eqs 4–7. Rank-deficient inputs are handled by first projecting onto the principal
subspace whose eigenvalues exceed ``rank_tol`` times the largest one. This is the
reference that the incremental learners are tested against, and what the analysis
uses to score learned features.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config.checks import check_block, check_nonconstant, check_positive_int


@dataclass(frozen=True)
class BatchSFA:
    """Result of :func:`batch_sfa`.

    ``y = (x - mean) @ W`` has zero mean and unit variance on the training data.

    Parameters
    ----------
    W : array of shape (features, n_components)
        The slow features' weights.
    mean : array of shape (features,)
        The training data's mean.
    delta : array of shape (n_components,)
        ``delta[j] = <ẏ_j²>``, ascending.
    """

    W: np.ndarray
    mean: np.ndarray
    delta: np.ndarray

    def transform(self, X) -> np.ndarray:
        X = check_block(X, n_features=self.W.shape[0])
        return (X - self.mean) @ self.W


def whiten_batch(X: np.ndarray, rank_tol: float = 1e-10) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre and whiten ``X`` by PCA, dropping directions with relative variance < ``rank_tol``.

    Returns ``(Z, S, mean)`` with ``Z = (X - mean) @ S`` of identity covariance.
    """
    mean = X.mean(axis=0)
    U = X - mean
    cov = U.T @ U / len(U)
    lam, V = np.linalg.eigh(cov)
    keep = lam > rank_tol * lam[-1]
    S = V[:, keep] / np.sqrt(lam[keep])
    return U @ S, S, mean


def batch_sfa(X, n_components: int, *, rank_tol: float = 1e-10) -> BatchSFA:
    """Exact linear SFA of ``X`` (rows are time) with ``n_components`` slow features.

    Parameters
    ----------
    X : array of shape (samples, features)
        The signal, rows in time (at least 3).
    n_components : int
        The slow features.
    rank_tol : float
        Directions whose variance is below ``rank_tol`` times the largest are dropped from the whitening.

    Returns
    -------
    BatchSFA
        The features' weights, the mean and the slownesses.
    """
    X = check_block(X, min_rows=3)
    check_nonconstant(X)
    n_components = check_positive_int(n_components, "n_components", source="batch_sfa")
    Z, S, mean = whiten_batch(X, rank_tol)
    if n_components > Z.shape[1]:
        raise ValueError(
            f"n_components={n_components} exceeds the input's rank ({Z.shape[1]} whitened dimensions)"
        )
    dZ = np.diff(Z, axis=0)
    delta, R = np.linalg.eigh(dZ.T @ dZ / len(dZ))
    W = S @ R[:, :n_components]
    return BatchSFA(W=W, mean=mean, delta=delta[:n_components])
