"""Curiosity for any reinforcement-learning agent: neurocur's VTA models as gymnasium wrappers.

- :mod:`~neurocur.rl.wrappers` — :class:`IntrinsicReward` (one environment) and
  :class:`IntrinsicRewardVector` (``gymnasium.vector``): the VTA model's dopamine added to the
  reward, the parts in ``info``;
- :mod:`~neurocur.rl.path` — the circuit's sensory path (EC, HPC, the VTA model) fed by the
  environment's observations;
- :mod:`~neurocur.rl.observations` — observations as frames and contexts.

docs/rl.md shows how to use them, with any VTA model (a third-party one included).
"""

from .observations import ObservationCoder
from .path import SensoryPath, model_circuit
from .wrappers import DEFAULT_FRAMES, IntrinsicReward, IntrinsicRewardVector

__all__ = ["IntrinsicReward", "IntrinsicRewardVector", "DEFAULT_FRAMES", "SensoryPath", "ObservationCoder",
           "model_circuit"]
