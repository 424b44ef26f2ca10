"""Pharmacology: drugs that act on the neuromodulator a region releases.

A region that releases a neuromodulator declares it (:attr:`Region.modulator
<neurocur.regions.base.Region.modulator>`, e.g. ``"da"`` for the VTA models, ``"ne"``
for the LC models) and passes every released level ``x`` through
:meth:`~neurocur.regions.base.Region.modulate` before it uses, emits or records it. A
drug lesion replaces that level, as a pharmacological manipulation of the transmitter
would, whatever the model computes upstream:

- ``clamp`` (``level``): x' = level, a constant tonic level (a saturating agonist, or a
  depletion with level 0);
- ``scale`` (``factor`` ≥ 0): x' = factor · x (an agonist above 1, an antagonist or a
  partial block below 1);
- ``noise`` (``sd`` > 0): x' = x + sd · ξ, ξ ~ N(0, 1) i.i.d. per release (a noisy
  transmitter; the draws come from the drug's own stream, so the region's other random
  draws are those of the untreated run).

Several drugs on one region apply in the order they are declared. Units are those of
the region's released level (docs/regions.md gives them per model). In a circuit file::

    [[lesion]]
    region = "LC"
    how = "clamp"
    level = 4.0

and from Python ``circuit.lesion("LC", "clamp", level=4.0)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..config import ConfigError, check_params, param

__all__ = ["DRUGS", "Clamp", "Scale", "Noise"]


@dataclass(frozen=True)
class Clamp:
    """x' = ``level``.

    Parameters
    ----------
    level : float
        The constant released level, in the region's units; required (a ``ConfigError`` without it).
    """

    level: float = param(math.nan, float, doc="the constant released level (the region's units); required")

    def __post_init__(self):
        _required(self, "level", "a number (the clamped level)")
        check_params(self)

    def apply(self, level: float, rng) -> float:
        return self.level


@dataclass(frozen=True)
class Scale:
    """x' = ``factor`` · x.

    Parameters
    ----------
    factor : float
        The gain (>= 0) on the released level: an agonist above 1, an antagonist or partial block below.
    """

    factor: float = param(1.0, float, low=0.0, doc="gain on the released level (agonist > 1, antagonist < 1)")

    def __post_init__(self):
        check_params(self)

    def apply(self, level: float, rng) -> float:
        return self.factor * level


@dataclass(frozen=True)
class Noise:
    """x' = x + ``sd`` · ξ, ξ ~ N(0, 1).

    Parameters
    ----------
    sd : float
        The standard deviation (> 0) of the added noise, in the region's units; required (a
        ``ConfigError`` without it).
    """

    sd: float = param(math.nan, float, low=0.0, low_open=True, doc="standard deviation of the added noise (the region's units); required")

    def __post_init__(self):
        _required(self, "sd", "a positive number (the noise's standard deviation)")
        check_params(self)

    def apply(self, level: float, rng) -> float:
        return level + self.sd * rng.standard_normal()


def _required(drug, name: str, expected: str) -> None:
    """A drug parameter without a default (NaN marks it unset) must be given."""
    value = getattr(drug, name)
    if isinstance(value, float) and math.isnan(value):
        raise ConfigError("<python>", name, expected, "nothing (the key is missing)")


#: Drug lesions by name; every region with a ``modulator`` accepts each of them.
DRUGS = {"clamp": Clamp, "scale": Scale, "noise": Noise}
