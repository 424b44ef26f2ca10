"""Each fitted parameter between its own scale and an unbounded scale, chosen by its bounds.

A hierarchical fit (:mod:`neurocur.fit.hierarchical`) puts a Gaussian group prior on every
parameter on an unbounded scale x (Huys et al. 2011, PLoS Comput Biol 7:e1002028). The scale
follows the parameter's bounds ``(low, high)``:

- both finite, **logit**: ``x = log((theta - low) / (high - theta))``,
  ``theta = low + (high - low) expit(x)``;
- only ``low`` finite, **log**: ``x = log(theta - low)``, ``theta = low + exp(x)``;
- only ``high`` finite, **neglog**: ``x = log(high - theta)``, ``theta = high - exp(x)``;
- neither, **identity**: ``x = theta``.

Every map is increasing in x, so an interval on x maps to an interval on the own scale.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from scipy.special import expit

from ..config import ConfigError

__all__ = ["Transforms"]


class Transforms:
    """The transforms of the parameters ``bounds`` names, in its order; arrays of shape (..., k) go between the
    own scale and the unbounded scale.

    Parameters
    ----------
    bounds : mapping of str to (float, float)
        ``{key: (low, high)}``, -inf/inf for no bound.
    source : str
        Where the bounds came from, for the messages.
    """

    def __init__(self, bounds: Mapping[str, tuple[float, float]], *, source: str = "bounds"):
        self.keys = list(bounds)
        pairs = []
        for k in self.keys:
            try:
                lo, hi = (float(v) for v in bounds[k])
            except (TypeError, ValueError):
                raise ConfigError(source, k, "a pair (low, high) of numbers", repr(bounds[k])) from None
            if np.isnan(lo) or np.isnan(hi) or not lo < hi or lo == np.inf or hi == -np.inf:
                raise ConfigError(source, k, "low < high (-inf and inf for no bound)", f"{lo}:{hi}")
            pairs.append((lo, hi))
        b = np.array(pairs, dtype=np.float64).reshape(len(self.keys), 2)
        self.low, self.high = b[:, 0], b[:, 1]
        lo_ok, hi_ok = np.isfinite(self.low), np.isfinite(self.high)
        self.logit, self.log, self.neglog = lo_ok & hi_ok, lo_ok & ~hi_ok, ~lo_ok & hi_ok
        self.kinds = [("logit" if a else "log" if b_ else "neglog" if c else "identity")
                      for a, b_, c in zip(self.logit, self.log, self.neglog)]

    def __len__(self) -> int:
        return len(self.keys)

    def to_own(self, x) -> np.ndarray:
        """theta on the parameters' own scale from x on the unbounded scale."""
        x = np.asarray(x, dtype=np.float64)
        lo, hi, width = self.low, self.high, self.high - self.low
        with np.errstate(invalid="ignore", over="ignore"):
            # the form subtracting from the nearer bound keeps theta's last digits near it
            logit = np.where(x > 0, hi - width * expit(-x), lo + width * expit(x))
            out = np.where(self.logit, logit, x)
            out = np.where(self.log, lo + np.exp(x), out)
            return np.where(self.neglog, hi - np.exp(x), out)

    def to_unbounded(self, theta) -> np.ndarray:
        """x on the unbounded scale from theta on the parameters' own scale (a bound maps to -inf or inf)."""
        theta = np.asarray(theta, dtype=np.float64)
        lo, hi = self.low, self.high
        with np.errstate(divide="ignore", invalid="ignore"):
            out = np.where(self.logit, np.log(theta - lo) - np.log(hi - theta), theta)
            out = np.where(self.log, np.log(theta - lo), out)
            return np.where(self.neglog, np.log(hi - theta), out)
