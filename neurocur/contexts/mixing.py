"""Mixing a driving force into frames, and scaling the frames to [0, 1] (section 4.1).

The synthetic world (:mod:`.synthetic`) shows a source of shape (n_steps, n_dims) through
a random ``(n_pixels, n_dims)`` mixing matrix: ``raw = signal @ mixing.T``, one row per
frame, then min-max scaled: ``"global"``, one (low, high) for all frames of the source
(or of one draw of a redrawn source), or ``"image"``, each frame by its own min and max.
A row's scaled values depend on that row and the limits alone, so a block of rows can be
scaled on its own (:func:`scale_frames`) and equals those rows of the scaled whole.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["NORMALISATIONS", "frame_limits", "mix_frames", "scale_frames"]

NORMALISATIONS = ("global", "image")


@njit(cache=True)
def _scale(raw, low, span, out):  # pragma: no cover - compiled
    """``(raw - low) / span`` elementwise into ``out`` (2-d): numpy's two passes fused, the same values."""
    for i in range(raw.shape[0]):
        for j in range(raw.shape[1]):
            out[i, j] = (raw[i, j] - low) / span
    return out


def mix_frames(signal: np.ndarray, mixing: np.ndarray, normalise: str, *, limits=None, symmetric=False):
    """Frames ``signal @ mixing.T`` scaled to [0, 1]; returns ``(frames, (low, high))``.

    ``normalise="global"`` maps ``[low, high]`` (the min and max over all frames, or
    ``±`` the largest magnitude if ``symmetric``, or the given ``limits``) to [0, 1];
    ``"image"`` scales each frame (row) by its own min and max (``limits`` and
    ``symmetric`` are then ignored and ``(0.0, 1.0)`` returned).

    Parameters
    ----------
    signal : array of float64, shape (n_steps, n_dims)
        The source, rows are time.
    mixing : array of float64, shape (n_pixels, n_dims)
        The mixing matrix.
    normalise : {"global", "image"}
        One (low, high) for all frames, or each frame by its own min and max.
    limits : tuple of float, optional
        ``(low, high)`` to map to [0, 1] with ``"global"`` instead of the frames' own.
    symmetric : bool
        ``"global"`` without ``limits``: map ``[-m, m]``, ``m`` the largest magnitude, instead of
        ``[min, max]`` (declared noise, centred).

    Returns
    -------
    frames : array of float64, shape (n_steps, n_pixels)
        The scaled frames.
    limits : tuple of float
        The ``(low, high)`` mapped to [0, 1].
    """
    raw = signal @ mixing.T
    limits = frame_limits(raw, normalise, symmetric) if limits is None or normalise == "image" else _checked_limits(*limits)
    return scale_frames(raw, normalise, limits, out=raw), limits


def frame_limits(raw: np.ndarray, normalise: str, symmetric: bool = False) -> tuple[float, float]:
    """The (low, high) that :func:`mix_frames` maps to [0, 1] for the mixed frames ``raw``.

    Checks that ``raw`` is finite and its range representable (a ``ValueError`` otherwise):
    min-max scaling then maps every value into [0, 1] exactly, because rounding is
    monotone (``low <= x <= high`` gives ``0 <= (x - low) / (high - low) <= 1``).

    Parameters
    ----------
    raw : array of float64
        The mixed, unscaled frames.
    normalise : {"global", "image"}
        The scaling (``"image"`` returns ``(0.0, 1.0)`` after the check).
    symmetric : bool
        ``±`` the largest magnitude instead of the min and max.

    Returns
    -------
    tuple of float
        ``(low, high)``, with ``high > low`` (a ``ValueError`` when every value is equal).
    """
    low, high = float(raw.min()), float(raw.max())
    if not np.isfinite(high - low):
        raise ValueError(f"cannot normalise frames: the mixed frames span [{low}, {high}], which is not finite "
                         "(a source with values too large?)")
    if normalise == "image":
        return 0.0, 1.0
    if symmetric:
        peak = max(high, -low)  # the largest magnitude, without a temporary |raw|
        low, high = -peak, peak
    return _checked_limits(low, high)


def _checked_limits(low, high) -> tuple[float, float]:
    low, high = float(low), float(high)
    if not high > low:
        raise ValueError("cannot normalise frames: every pixel of every frame has the same value")
    return low, high


def scale_frames(raw: np.ndarray, normalise: str, limits, *, out=None) -> np.ndarray:
    """The mixed frames ``raw`` (rows) scaled to [0, 1] as :func:`mix_frames` does, into ``out`` if given.

    A row's values depend on that row (and ``limits``) alone, so scaling a block of rows
    gives exactly the rows of the scaled whole.

    Parameters
    ----------
    raw : array of float64, shape (n, n_pixels)
        Mixed, unscaled frames (rows).
    normalise : {"global", "image"}
        The scaling; any other value is a ``ValueError``.
    limits : tuple of float
        ``(low, high)`` of ``"global"`` (from ``frame_limits``); not read by ``"image"``.
    out : array of float64, optional
        Where to write the frames (may be ``raw`` itself); a new array by default.

    Returns
    -------
    array of float64, shape (n, n_pixels)
        The scaled frames (``out`` when given).
    """
    if normalise == "global":
        low, high = _checked_limits(*limits)
        return _scale(raw, low, high - low, np.empty(raw.shape) if out is None else out)
    if normalise == "image":
        low = raw.min(axis=1, keepdims=True)
        span = raw.max(axis=1, keepdims=True) - low
        flat = span[:, 0] == 0.0
        frames = np.subtract(raw, low, out=out)
        np.divide(frames, np.where(flat[:, None], 1.0, span), out=frames)
        frames[flat] = 0.5
        return frames
    raise ValueError(f"normalise must be one of {', '.join(map(repr, NORMALISATIONS))}; got {normalise!r}")


class SourceFrames:
    """The frames of one source in a run: its mixing matrix and its current draw.

    ``whole=True`` (a replayed source): each draw's frames are rendered whole, read-only
    (:meth:`frames`; a visit is a view of them). ``whole=False`` (a source redrawn every
    epoch): the mixed, unscaled frames are kept in one buffer that every draw reuses, with
    the draw's limits; :meth:`scale_rows` scales the rows a visit shows, and :meth:`frames`
    renders the whole draw only when asked for.
    """

    def __init__(self, mixing: np.ndarray, normalise: str, *, symmetric: bool, whole: bool):
        mixing.flags.writeable = False
        self.mixing, self.normalise, self.symmetric, self.whole = mixing, normalise, symmetric, whole
        self._raw = self._frames = None

    def show(self, signal: np.ndarray) -> None:
        """Make ``signal`` (n_steps, n_dims) the current draw."""
        signal.flags.writeable = False
        self.signal = signal
        if self.whole:
            self._frames, self.limits = self.render(signal)
            self._frames.flags.writeable = False
            return
        if self._raw is None:
            self._raw = np.empty((len(signal), len(self.mixing)))
        np.matmul(signal, self.mixing.T, out=self._raw)
        self.limits = frame_limits(self._raw, self.normalise, self.symmetric)
        self._frames = None

    def render(self, signal: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
        """``(frames, limits)`` of ``signal`` through this source's mixing (:func:`mix_frames`)."""
        return mix_frames(signal, self.mixing, self.normalise, symmetric=self.symmetric)

    def frames(self) -> np.ndarray:
        """Every frame of the current draw, (n_steps, n_pixels), read-only."""
        if self._frames is None:
            self._frames = scale_frames(self._raw, self.normalise, self.limits, out=np.empty_like(self._raw))
            self._frames.flags.writeable = False
        return self._frames

    def scale_rows(self, first: int, out: np.ndarray) -> None:
        """The frames of steps ``first .. first + len(out) - 1`` of the current draw, scaled into ``out``."""
        scale_frames(self._raw[first : first + len(out)], self.normalise, self.limits, out=out)
