"""The quality measure of a learned feature: |Pearson correlation| with a known signal."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["abs_corr"]


def abs_corr(a, b) -> float:
    """|Pearson correlation| of two equally long series; NaN when either is constant or shorter than 2.

    Parameters
    ----------
    a, b : array_like of float
        The two series.

    Returns
    -------
    float
        In [0, 1], or NaN.
    """
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if len(a) < 2 or np.std(a) == 0.0 or np.std(b) == 0.0:
        return math.nan
    return float(abs(np.corrcoef(a, b)[0, 1]))
