"""Input checks shared by every learner.

Every public learner entry point checks its data once per call, before the compiled
loop: :func:`check_block` (or scikit-learn's ``validate_data`` for the
scikit-learn estimators IncSFA, CCIPCA and MCA, see ``_estimator``) and
:func:`check_scale`, so a bad input fails with one clear ``ValueError`` that says what
was expected, never with a silent NaN or all-zero output further down a compiled loop.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def check_block(X, *, name: str = "X", n_features: int | None = None, min_rows: int = 1) -> np.ndarray:
    """Return ``X`` as a C-contiguous float64 array of shape (time, features).

    Raises ``ValueError`` for a wrong number of dimensions, a non-numeric dtype,
    too few rows, a feature count other than ``n_features``, or NaN/inf values.
    """
    arr = np.asarray(X)
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"{name} must hold real numbers (bool, int or float); got dtype {arr.dtype}")
    if arr.ndim != 2:
        raise ValueError(f"{name} must be 2-d with shape (time, features); got shape {arr.shape}")
    if arr.shape[0] < min_rows:
        raise ValueError(f"{name} must have at least {min_rows} row(s) (time steps); got {arr.shape[0]}")
    if n_features is not None and arr.shape[1] != n_features:
        raise ValueError(f"{name} must have {n_features} features (columns); got {arr.shape[1]}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.isfinite(arr).all():
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"{name} contains NaN or inf (first at row {bad[0]}, column {bad[1]})")
    return arr


def check_nonconstant(X: np.ndarray, *, name: str = "X") -> None:
    """Raise ``ValueError`` when every column of ``X`` is constant (zero variance)."""
    if X.shape[0] < 2 or not np.any(np.ptp(X, axis=0) > 0):
        raise ValueError(f"{name} has zero variance: every feature is constant over time")


def check_positive_int(value, name: str) -> int:
    """Return ``value`` as an int, raising ``ValueError`` unless it is a positive integer."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive integer; got {value!r}")
    return int(value)


def check_fraction(value, name: str, *, open_low: bool = True, open_high: bool = False) -> float:
    """Return ``value`` as a float in (0, 1] (bounds' openness configurable), else ``ValueError``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in (0, 1]; got {value!r}") from None
    low_ok = v > 0 if open_low else v >= 0
    high_ok = v < 1 if open_high else v <= 1
    if not (low_ok and high_ok and np.isfinite(v)):
        lo = "(0" if open_low else "[0"
        hi = "1)" if open_high else "1]"
        raise ValueError(f"{name} must be in {lo}, {hi}; got {value!r}")
    return v


def check_random_state(random_state) -> np.random.Generator:
    """Turn ``None``, an int, a ``SeedSequence`` or a ``Generator`` into a ``Generator``."""
    if isinstance(random_state, np.random.Generator):
        return random_state
    if random_state is None or isinstance(random_state, (int, np.integer, np.random.SeedSequence)):
        return np.random.default_rng(random_state)
    raise ValueError(
        f"random_state must be None, an int, a numpy SeedSequence or a numpy Generator; got {type(random_state).__name__}"
    )


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
