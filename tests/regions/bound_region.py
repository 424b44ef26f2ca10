"""The one helper the region tests share: a region bound to a minimal world and reset, outside any circuit."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np


def minimal_world(n_contexts: int = 2, n_states: int = 4) -> SimpleNamespace:
    """The two facts a region reads from its world when it is bound: the counts of contexts and states."""
    return SimpleNamespace(n_contexts=n_contexts, n_states=n_states)


def bound(cls, name: str = "", *, world=None, seed: int = 0, **params):
    """A ``cls`` region with keyword ``params``, bound to ``world`` (default ``minimal_world()``) and
    reset with ``default_rng(seed)``."""
    region = cls(name or cls.__name__, **params)
    region.bind(minimal_world() if world is None else world)
    region.reset(np.random.default_rng(seed))
    return region
