"""Tiny gymnasium environments with vector observations and no rendering, registered when this
module is imported (as a package of environments registers its own): the gym world's tests name
this module in ``imports`` or as the ``module:`` of an id.

``neurocur_test/Walk-v0``: a walk x in [-2, 2] that starts uniform in [-1, 1] and moves by -0.25
(action 0) or +0.25 (action 1), ending when |x| reaches 2; at step t the observation is
[x, min(t, 10), x^2, t mod 5], in Box([-2, 0, 0, 0], [2, 10, 4, 4]). ``neurocur_test/UnboundedWalk-v0``:
the same observations in Box(-inf, inf). ``neurocur_test/ShortWalk-v0``: the first three values
only. ``neurocur_test/Undeclared-v0``: the walk of a class whose metadata declares no render modes
(as neurogym's tasks). Each env keeps every observation it returned (``history``), so that a test can scale them
itself. Like many task packages' environments, they take no ``render_mode``.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

IDS = ("neurocur_test/Walk-v0", "neurocur_test/UnboundedWalk-v0", "neurocur_test/ShortWalk-v0",
       "neurocur_test/Undeclared-v0")
LOW, HIGH = np.array([-2.0, 0.0, 0.0, 0.0]), np.array([2.0, 10.0, 4.0, 4.0])


class Walk(gymnasium.Env):
    """The walk (module docstring); ``bounded=False``: in Box(-inf, inf); ``size``: the first values only."""

    metadata = {"render_modes": []}

    def __init__(self, bounded: bool = True, size: int = 4):
        self.size = size
        low, high = (LOW[:size], HIGH[:size]) if bounded else (np.full(size, -np.inf), np.full(size, np.inf))
        self.observation_space = spaces.Box(low, high, dtype=np.float64)
        self.action_space = spaces.Discrete(2)
        self.history: list[np.ndarray] = []

    def _observe(self) -> np.ndarray:
        obs = np.array([self.x, min(self.t, 10), self.x**2, self.t % 5])[: self.size]
        self.history.append(obs)
        return obs.copy()

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.t = float(self.np_random.uniform(-1.0, 1.0)), 0
        return self._observe(), {}

    def step(self, action):
        self.x = float(np.clip(self.x + (0.25 if action else -0.25), -2.0, 2.0))
        self.t += 1
        return self._observe(), 0.0, abs(self.x) >= 2.0, False, {}


class Undeclared(Walk):
    """The walk, its metadata without ``render_modes``."""

    metadata = {"tags": ["test"]}


for _id, _class, _kwargs in zip(IDS, ("Walk", "Walk", "Walk", "Undeclared"), ({}, {"bounded": False}, {"size": 3}, {})):
    if _id not in gymnasium.registry:
        gymnasium.register(_id, entry_point=f"{__name__}:{_class}", kwargs=_kwargs)
