"""The numerical range of the incremental learners' input (:func:`check_scale`), checked with
the other input checks (:mod:`neurocur.config.checks`) once per call."""

from __future__ import annotations

import numpy as np
from numba import njit

#: The accepted scale of the incremental learners' input. Their loops form fourth powers
#: of the data: CCIPCA's new length ||a v̂ + b r||² = a² + 2ab (r·v̂) + b² ||r||² with
#: a ∝ λ ∝ x² (Algorithm 2, ``_kernels.ccipca_step``), and CIMCA's ((z·w) z)² for MCA.
#: float64 spans about 1e±308, so data near 1e±77 overflows to inf/NaN or underflows to
#: zero eigenvalues (all-zero features). 1e±60 leaves 68 orders of magnitude of headroom
#: in the fourth power for the number of features and the spread of the eigenvalues.
MAX_SCALE = 1e60
MIN_SCALE = 1e-60


@njit(cache=True, nogil=True)
def _largest_abs(flat):  # pragma: no cover - compiled
    """max |x| of a 1-d float array in one pass; NaN when any value is NaN (inf stays inf).
    The loop is branch-free, so it is vectorised."""
    big = 0.0
    nan = False
    for i in range(flat.shape[0]):
        a = abs(flat[i])
        nan |= a != a
        big = a if a > big else big
    return np.nan if nan else big


def check_scale(X: np.ndarray, *, name: str = "X", first: bool = False, centred: bool = True) -> None:
    """Raise ``ValueError`` when the scale of ``X`` is outside what the learners' loops can represent.

    Every block: the largest absolute value must be at most :data:`MAX_SCALE`. The first
    block of a fresh learner also sets the scale of its estimates, so its own scale must
    be at least :data:`MIN_SCALE`: the largest range (max − min) of a feature for a
    learner that centres its input (CCIPCA, IncSFA), the largest absolute value for one
    that learns the second moment (MCA). The message names the scale found and the
    range accepted.
    """
    accepted = f"accepted: largest |value| <= {MAX_SCALE:g}"
    if first:
        accepted += f" and, on the first fit, {'largest feature range' if centred else 'largest |value|'} >= {MIN_SCALE:g}"
    biggest = _largest_abs(X.reshape(-1)) if X.size else 0.0
    if not np.isfinite(biggest):
        raise ValueError(f"{name} must be finite: it contains NaN or inf")
    if biggest > MAX_SCALE:
        raise ValueError(
            f"{name} is out of the learners' numerical range: its largest |value| is {biggest:.3g}, "
            f"which would overflow ({accepted}); rescale {name}, e.g. with sklearn's StandardScaler"
        )
    if first:
        low = float(np.ptp(X, axis=0).max()) if centred else biggest
        if low < MIN_SCALE:
            what = "largest feature range (max - min)" if centred else "largest |value|"
            raise ValueError(
                f"{name} is out of the learners' numerical range: its {what} is {low:.3g}, "
                f"which would underflow to zero eigenvalues ({accepted}); rescale {name}, "
                f"e.g. with sklearn's StandardScaler"
            )
