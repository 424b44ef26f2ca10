"""From a gymnasium observation to what the circuit's sensory path reads: a frame and a context.

A **frame** is the observation as the EC reads a frame of a world (``Episode.frames``: a float
vector in [0, 1]). A **context** is the index of the part of the observation space the
observation falls in: the VTA models keep their memory (visit counts, previous errors) per
context, as they do per context of a world (docs/regions.md, "VTA").

- A vector ``Box`` (rank 1): each dimension is scaled to [0, 1] by its bounds, or, where a bound
  is infinite, squashed by the logistic function. Its context is the cell of a regular grid of
  ``bins`` cells per dimension over the bounds (``contexts="grid"``, the default when every bound
  is finite), or a SimHash code (``contexts="simhash"``).
- An image ``Box`` (rank 3 with 1, 3 or 4 channels, or rank 2; ``uint8`` 0-255, as ``rgb_array``
  renders): the frame is the grey level of every ``stride``-th pixel in each direction, so that at
  most ``image_size`` pixels a side remain, divided by 255. Its context is a SimHash code.
- Any other space is a :class:`~neurocur.config.ConfigError` naming the space, and so is a vector
  Box whose finite bounds are so far apart that ``high - low`` overflows a float64.

Each observation is checked against the space as it is coded (:meth:`ObservationCoder.check`,
:meth:`ObservationCoder.checked_context`): its shape, real numbers (bool, integer or float), every
value finite (else a ConfigError naming the index), in one compiled pass that also counts the
values outside the bounds; those are clipped to the bounds in the frame (environments emit them:
a Box's bounds are often a guide, not a guarantee), and the count is returned.

SimHash (Charikar 2002; as a count-based exploration bonus, Tang et al. 2017, "#Exploration",
*NeurIPS* 30): the signs of ``k`` random projections ``A (x - 1/2)`` of the frame, ``A`` with
standard normal entries drawn from the seed, read as a ``k``-bit number: 2**k contexts, and
frames close in the frame space share their code.
"""

from __future__ import annotations

from typing import NoReturn

import numpy as np
from gymnasium import spaces
from numba import njit
from scipy.special import expit

from ..config import ConfigError

__all__ = ["ObservationCoder", "CONTEXTS", "MAX_CONTEXTS"]

#: The ways of cutting an observation space into contexts.
CONTEXTS = ("grid", "simhash")
#: The most contexts: the VTA models and HPC keep arrays with one entry per context.
MAX_CONTEXTS = 2**16


class ObservationCoder:
    """Frames and contexts of the observations of ``space`` (see the module's docstring).

    Parameters
    ----------
    space : gymnasium.spaces.Box
        The observation space: a vector Box or an image Box.
    contexts : str, optional
        ``"grid"``, ``"simhash"`` or ``None`` (grid for a vector Box with finite bounds, SimHash otherwise).
    bins : int
        Grid cells per dimension.
    hash_bits : int
        k of SimHash.
    image_size : int
        The largest side of an image frame.
    rng : numpy.random.Generator
        Draws SimHash's projection.
    source : str
        Names the caller in errors.
    """

    def __init__(self, space, *, contexts: str | None = None, bins: int = 8, hash_bits: int = 8,
                 image_size: int = 16, rng: np.random.Generator, source: str = "IntrinsicReward"):
        if not isinstance(space, spaces.Box) or not _is_vector(space) and not _is_image(space):
            raise ConfigError(source, "observation_space",
                              "a Box of rank 1 (a vector) or an image Box (H, W) or (H, W, C) with C in 1, 3, 4",
                              _describe(space))
        self.image, self.shape, self.source = _is_image(space), space.shape, source
        self.space_text = f"(observation space {space})"
        with np.errstate(over="ignore"):
            too_wide = np.isfinite(space.low) & np.isfinite(space.high) & ~np.isfinite(
                space.high.astype(np.float64) - space.low.astype(np.float64))
        if too_wide.any():
            raise ConfigError(source, "observation_space", "bounds whose width high - low is a finite float64 in every "
                              f"dimension (it overflows in dimension {int(np.flatnonzero(too_wide)[0])})",
                              _describe(space))
        self.bounds = np.stack([space.low.astype(np.float64).ravel(), space.high.astype(np.float64).ravel()])
        # an image of uint8 in a Box of 0-255 holds only finite values within its bounds: nothing to scan
        self.full_range = bool(self.image and (self.bounds[0] == 0).all() and (self.bounds[1] == 255).all())
        finite = not self.image and bool(np.all(np.isfinite(space.low)) and np.all(np.isfinite(space.high)))
        if contexts is None:
            contexts = "grid" if finite else "simhash"
        if contexts not in CONTEXTS:
            raise ConfigError(source, "contexts", f"one of {', '.join(CONTEXTS)}", repr(contexts))
        if contexts == "grid" and not finite:
            raise ConfigError(source, "contexts", "'simhash' for an image or a Box with an infinite bound",
                              f"'grid' on {_describe(space)}")
        for key, value, low in (("bins", bins, 1), ("hash_bits", hash_bits, 1), ("image_size", image_size, 1)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
                raise ConfigError(source, key, f"an integer >= {low}", repr(value))
        if 2 ** hash_bits > MAX_CONTEXTS:
            raise ConfigError(source, "hash_bits", f"2 ** hash_bits <= {MAX_CONTEXTS} contexts", repr(hash_bits))
        self.contexts = contexts
        if self.image:
            h, w = space.shape[:2]
            self.stride = (max(1, -(-h // image_size)), max(1, -(-w // image_size)))
            self.n_pixels = len(range(0, h, self.stride[0])) * len(range(0, w, self.stride[1]))
        else:
            low, high = space.low.astype(np.float64), space.high.astype(np.float64)
            self.bounded = bounded = np.isfinite(low) & np.isfinite(high)
            self.unbounded = not bounded.all()
            self.low = np.where(bounded, low, 0.0)
            self.span = np.where(bounded & (high > low), high - low, 1.0)
            self.n_pixels = space.shape[0]
            self.table = np.stack([*self.bounds, self.low, self.span, bounded])  # what the compiled pass reads
        if contexts == "grid":
            self.bins = int(bins)
            if self.bins ** self.n_pixels > MAX_CONTEXTS:
                raise ConfigError(source, "bins", f"bins ** {self.n_pixels} dimensions <= {MAX_CONTEXTS} contexts "
                                  "(or contexts='simhash')", repr(bins))
            self.n_contexts = self.bins ** self.n_pixels
            self.radix = self.bins ** np.arange(self.n_pixels, dtype=np.int64)
        else:
            self.projection = rng.standard_normal((self.n_pixels, int(hash_bits)))
            self.half_sums = 0.5 * self.projection.sum(axis=0)  # (x - 1/2) A > 0  <=>  x A > A's column sums / 2
            self.hashing = np.vstack([self.projection, self.half_sums])
            self.n_contexts = 2 ** int(hash_bits)
            self.radix = 2 ** np.arange(int(hash_bits), dtype=np.int64)

    def frames(self, observations: np.ndarray) -> np.ndarray:
        """Observations stacked along a first axis (an array) as frames: float64 rows in [0, 1]."""
        if self.image:
            x = observations[:, :: self.stride[0], :: self.stride[1]]
            if x.ndim == 4:
                x = x[..., :3].mean(axis=3)
            return x.reshape(len(x), -1) / 255.0
        z = observations - self.low  # float64 (low is)
        z /= self.span
        if self.unbounded:  # low 0 and span 1 there: the logistic function of the observation
            z = np.where(self.bounded, z, expit(z))
        return np.minimum(np.maximum(z, 0.0, out=z), 1.0, out=z)

    def check(self, observation) -> tuple[np.ndarray, int]:
        """``observation`` as an array, checked against the space, and the number of its values
        outside the bounds. A shape other than the space's, values that are not real numbers (bool,
        integer or float) or a value that is not finite is a one-line
        :class:`~neurocur.config.ConfigError` naming the index and the space."""
        x = self._array(observation)
        if x.dtype == np.uint8:  # an image's
            if self.full_range:
                return x, 0
            status = _scan(x.reshape(-1).astype(np.float64), self.bounds)
        else:
            status = _scan(x.reshape(-1), self.bounds)
        return x, status if status >= 0 else self._not_finite(x, status)

    def checked_context(self, observation) -> tuple[int, int]:
        """The context of one observation and the number of its values outside the bounds, checked as
        :meth:`check` does: for a vector Box, the check and :meth:`contexts_of` of its :meth:`frames`
        in one compiled pass (a step of the count path pays no array temporaries). A grid cell is
        the same exactly; a SimHash code the same but where a projection of the frame lies within
        rounding of its threshold (the logistic and the dot product are summed in another order)."""
        if self.image:
            x, outside = self.check(observation)
            return int(self.contexts_of(self.frames(x[None]))[0]), outside
        x = self._array(observation)
        if self.contexts == "grid":
            key, status = _grid_context(x, self.table, self.bins)
        else:
            key, status = _hash_context(x, self.table, self.hashing)
        return key, status if status >= 0 else self._not_finite(x, status)

    def context_of(self, observation) -> int:
        """The context of one observation (:meth:`checked_context`'s first part)."""
        return self.checked_context(observation)[0]

    def _array(self, observation) -> np.ndarray:
        """The observation as an array of the space's shape holding real numbers (float32 or float64,
        as the compiled passes read them), or a ConfigError."""
        x = observation if type(observation) is np.ndarray else np.asarray(observation)
        if x.shape != self.shape:
            raise ConfigError(self.source, "observation", f"an array of shape {self.shape} {self.space_text}",
                              f"an array of shape {x.shape}")
        if x.dtype != np.float64 and x.dtype != np.float32:
            if x.dtype.kind not in "biuf":
                raise ConfigError(self.source, "observation", f"real numbers (bool, integer or float) "
                                  f"{self.space_text}", f"dtype {x.dtype}")
            if not (self.image and x.dtype == np.uint8):
                x = x.astype(np.float64)
        return x

    def _not_finite(self, x: np.ndarray, status: int) -> NoReturn:
        """The ConfigError naming the value of ``x`` that is not finite, from a compiled pass's
        ``status`` (:func:`_scan`)."""
        index = ", ".join(str(int(i)) for i in np.unravel_index(-1 - status, self.shape))
        raise ConfigError(self.source, f"observation[{index}]", f"a finite number {self.space_text}",
                          str(float(x.reshape(-1)[-1 - status])))

    def contexts_of(self, frames: np.ndarray) -> np.ndarray:
        """The context of each frame (rows): its grid cell, or its SimHash code."""
        if self.contexts == "grid":
            return np.minimum((frames * self.bins).astype(np.int64), self.bins - 1) @ self.radix
        return ((frames @ self.projection) > self.half_sums) @ self.radix


@njit(cache=True)
def _scan(x, bounds):
    """The check of an observation's values ``x`` (flat; ``bounds`` its rows low and high), in one
    pass: ``-1 - i`` for the first value ``i`` that is not finite, else the number of values
    outside the bounds."""
    outside = 0
    for i in range(x.shape[0]):
        v = x[i]
        if not np.isfinite(v):
            return -1 - i
        if v < bounds[0, i] or v > bounds[1, i]:
            outside += 1
    return outside


@njit(cache=True)
def _frame_value(x, table, i):
    """Dimension ``i`` of an observation's frame (:meth:`ObservationCoder.frames`; ``table``'s rows
    2-4 are its ``low``, ``span`` and ``bounded``)."""
    z = (x[i] - table[2, i]) / table[3, i]
    if table[4, i] == 0.0:
        z = 1.0 / (1.0 + np.exp(-z))
    return min(max(z, 0.0), 1.0)


@njit(cache=True)
def _grid_context(x, table, bins):
    """(the grid cell of an observation, :func:`_scan`'s status of it); the cell is 0 where the status is < 0."""
    status = _scan(x, table)
    key = 0
    if status < 0:
        return key, status
    radix = 1
    for i in range(x.shape[0]):
        key += min(int(_frame_value(x, table, i) * bins), bins - 1) * radix
        radix *= bins
    return key, status


@njit(cache=True)
def _hash_context(x, table, hashing):
    """(the SimHash code of an observation, :func:`_scan`'s status of it); ``hashing`` is the
    projection with the half sums of its columns as a last row; the code is 0 where the status is < 0."""
    status = _scan(x, table)
    key = 0
    if status < 0:
        return key, status
    n = x.shape[0]
    z = np.empty(n)
    for i in range(n):
        z[i] = _frame_value(x, table, i)
    for j in range(hashing.shape[1]):
        s = 0.0
        for i in range(n):
            s += z[i] * hashing[i, j]
        if s > hashing[n, j]:
            key += 1 << j
    return key, status


def _is_vector(space) -> bool:
    return len(space.shape) == 1


def _is_image(space) -> bool:
    shape = space.shape
    return space.dtype == np.uint8 and (len(shape) == 2 or len(shape) == 3 and shape[2] in (1, 3, 4))


def _describe(space) -> str:
    return f"{type(space).__name__} {space}"
