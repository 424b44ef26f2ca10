"""What a row of the gym world (``neurocur.contexts.gym``) shows: an environment's render as a gray
frame, or its observation vector scaled to [0, 1].

* ``to_frame`` (``observation = "render"``): an ``rgb_array`` render converted to gray (ITU-R BT.601
  luma) and resized to the world's ``frame_shape`` (averaging bins to shrink, repeating pixels to
  enlarge), in [0, 1].
* ``VectorScale`` (``observation = "vector"``): the observation flattened
  (``gymnasium.spaces.flatten``) and scaled per dimension by the bounds of the flattened space, a bound
  that is infinite or at least ``UNBOUNDED`` replaced by the declared ``observation_range``: a fixed
  scaling, so that a frame's value means the same observation throughout a run.
"""

from __future__ import annotations

from collections.abc import Sequence

import gymnasium
import numpy as np

from ..config import ConfigError, describe

__all__ = ["UNBOUNDED", "VectorScale", "to_frame"]

_LUMA = np.array([0.299, 0.587, 0.114])
#: a bound at least this large in magnitude stands for "unbounded" (float32's largest value)
UNBOUNDED = float(np.finfo(np.float32).max)


def to_frame(rgb: np.ndarray, shape: Sequence[int]) -> np.ndarray:
    """An (H, W, 3) ``uint8`` image as a flat gray frame of ``shape`` (height, width), in [0, 1].

    Gray is the BT.601 luma. Each axis is shrunk by averaging the pixels of ``n`` bins of
    equal size (to within one pixel), or enlarged by repeating pixels (nearest neighbour).

    Parameters
    ----------
    rgb : array of uint8, shape (H, W, 3)
        An RGB image (an environment's ``rgb_array`` render).
    shape : sequence of int
        ``(height, width)`` of the frame.

    Returns
    -------
    array of float64, shape (height * width,)
        The gray frame, row-major, in [0, 1].
    """
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) RGB image; got shape {rgb.shape}")
    img = rgb.astype(np.float64)
    for axis, n in enumerate(shape):  # resizing first, then gray: both are linear, resizing is cheaper
        size = img.shape[axis]
        if n < size:
            edges = np.arange(n) * size // n
            counts = np.diff(np.append(edges, size)).reshape((-1, 1, 1) if axis == 0 else (-1, 1))
            img = np.add.reduceat(img, edges, axis=axis) / counts
        elif n > size:
            img = np.take(img, np.arange(n) * size // n, axis=axis)
    return np.clip((img @ _LUMA).ravel() / 255.0, 0.0, 1.0)


class VectorScale:
    """The scaling of a vector observation to [0, 1] (module docstring: ``observation = "vector"``).

    ``space``: the environment's observation space (flattenable); ``declared``: the
    ``(low, high)`` of its unbounded dimensions, or None. ``where``, ``env``: the parameter
    class and the environment id, named by the errors (ValueError, or ConfigError naming
    ``observation_range``).

    Parameters
    ----------
    space : gymnasium.spaces.Space
        The environment's observation space; it must flatten to a vector (``is_np_flattenable``,
        a ``ValueError`` otherwise).
    declared : sequence of float, optional
        ``(low, high)`` that replaces each unbounded bound of the flattened space (the parameters'
        ``observation_range``); None when none is declared (then an unbounded dimension is a
        ``ConfigError`` naming ``observation_range``).
    where : str
        The parameter class, named by a ``ConfigError``.
    env : str
        The environment id, named by the errors.
    """

    def __init__(self, space: gymnasium.spaces.Space, declared: Sequence[float] | None, *, where: str, env: str):
        if not space.is_np_flattenable:
            raise ValueError(f"gymnasium environment {env!r}: observation = 'vector' needs an observation space that "
                             f"flattens to a vector (Box, Discrete, MultiDiscrete, MultiBinary, Dict or Tuple of them); "
                             f"got {space}")
        self.space, self.env = space, env
        flat = gymnasium.spaces.flatten_space(space)
        low, high = flat.low.astype(np.float64).ravel(), flat.high.astype(np.float64).ravel()
        open_low, open_high = ~(np.abs(low) < UNBOUNDED), ~(np.abs(high) < UNBOUNDED)
        if (open_low | open_high).any():
            if declared is None:
                raise ConfigError(where, "observation_range", f"[low, high] for the {int((open_low | open_high).sum())} "
                                  f"unbounded dimension(s) of the observation of {env!r} (of {low.size})", "none")
            low, high = np.where(open_low, declared[0], low), np.where(open_high, declared[1], high)
            if not (high > low)[open_low | open_high].all():
                raise ConfigError(where, "observation_range", f"a range whose low is below every finite upper bound "
                                  f"and whose high is above every finite lower bound of {env!r}'s observation",
                                  describe(list(declared)))
        self.low, self.span = low, np.where(high > low, high - low, np.inf)  # a constant dimension: 0 throughout

    @property
    def size(self) -> int:
        """The number of values of a flattened observation."""
        return self.low.size

    def __call__(self, observation) -> np.ndarray:
        """``observation`` flattened and scaled to [0, 1]; a ValueError if it is not finite."""
        x = np.asarray(gymnasium.spaces.flatten(self.space, observation), dtype=np.float64).ravel()
        if not np.isfinite(x).all():
            raise ValueError(f"gymnasium environment {self.env!r} returned a non-finite observation: {x.tolist()}")
        return np.clip((x - self.low) / self.span, 0.0, 1.0)
