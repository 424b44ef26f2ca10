"""Public checks shared across layers: input blocks (time × features), seeds and the scalar
arguments of functions called from Python.

A scalar argument is checked by a :class:`~.params.ParamSpec`, as every parameter is
(:func:`check_positive_int`, :func:`check_fraction`), so its error is a
:class:`~.errors.ConfigError` naming the argument and what was expected. A data block is
checked once per call, before any compiled loop (:func:`check_block`,
:func:`check_nonconstant`), so a bad input fails with one clear ``ValueError`` that says what
was expected, never with a silent NaN or all-zero output further down.
"""

from __future__ import annotations

import numpy as np

from .params import ParamSpec

__all__ = ["RANDOM_STATE", "check_block", "check_fraction", "check_nonconstant", "check_positive_int", "check_random_state"]

#: A seed (``random_state``): None, an int >= 0, a numpy ``SeedSequence`` or a numpy ``Generator``.
RANDOM_STATE = ParamSpec(int, low=0, optional=True, classes=(np.random.SeedSequence, np.random.Generator))
_POSITIVE_INT = ParamSpec(int, low=1)
_FRACTION = ParamSpec(float, low=0.0, high=1.0, low_open=True)


def check_positive_int(value, name: str, *, source="<python>") -> int:
    """``value`` as an int >= 1, else a :class:`~.errors.ConfigError` naming ``source`` and ``name``.

    Parameters
    ----------
    value : int
        The value checked.
    name : str
        Its key, named in a message.
    source : str
        The file named in a message.

    Returns
    -------
    int
        The value.
    """
    return _POSITIVE_INT.coerce(value, source=source, key=name)


def check_fraction(value, name: str, *, source="<python>") -> float:
    """``value`` as a float in (0, 1], else a :class:`~.errors.ConfigError` naming ``source`` and ``name``.

    Parameters
    ----------
    value : float
        The value checked.
    name : str
        Its key, named in a message.
    source : str
        The file named in a message.

    Returns
    -------
    float
        The value.
    """
    return _FRACTION.coerce(value, source=source, key=name)


def check_block(X, *, name: str = "X", n_features: int | None = None, min_rows: int = 1) -> np.ndarray:
    """Return ``X`` as a C-contiguous float64 array of shape (time, features).

    Raises ``ValueError`` for a wrong number of dimensions, a non-numeric dtype,
    too few rows, a feature count other than ``n_features``, or NaN/inf values.

    Parameters
    ----------
    X : array_like
        The block of samples.
    name : str
        Its name in a message.
    n_features : int, optional
        The number of columns it must have.
    min_rows : int
        The fewest rows it may have.

    Returns
    -------
    numpy.ndarray
        ``X`` as a C-contiguous float64 array.
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
    """Raise ``ValueError`` when every column of ``X`` is constant (zero variance).

    Parameters
    ----------
    X : numpy.ndarray
        The block of samples (time, features).
    name : str
        Its name in the message.
    """
    if X.shape[0] < 2 or not np.any(np.ptp(X, axis=0) > 0):
        raise ValueError(f"{name} has zero variance: every feature is constant over time")


def check_random_state(random_state, *, name: str = "random_state", source="<python>") -> np.random.Generator:
    """A ``Generator`` from a seed that :data:`RANDOM_STATE` accepts (a ``Generator`` is returned as it is).

    Parameters
    ----------
    random_state : int, numpy.random.SeedSequence, numpy.random.Generator or None
        The seed or generator.
    name : str
        Its key, named in a message.
    source : str
        The file named in a message.

    Returns
    -------
    numpy.random.Generator
        The generator.
    """
    return np.random.default_rng(RANDOM_STATE.coerce(random_state, source=source, key=name))
