"""The synthetic world's contexts paying rewards that change by blocks of visits: utility that falls and rises.

Not in the paper. For the adaptive-gain LC (Aston-Jones & Cohen 2005, Annu Rev Neurosci
28:403): they propose that the LC leaves the phasic mode for the tonic one when the
utility of the current task falls (reward depletion, or a reversal), so that the animal
disengages and explores, and returns to the phasic mode when utility rises again. The
frames are the synthetic world's (:mod:`.synthetic`: each context shows a source through
a random mixing); block k of ``block_visits`` consecutive visits (counted over every
context, from the run's start) pays ``blocks[k][c]`` for a visit of context c; after the
last block, the last block's rewards go on. Without ``blocks``, one block pays 1.0 for a visit
of each context (so that the world builds from its defaults, whatever its contexts).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from neurocur.config import ConfigError, ParamSpec, describe, param, spec_param

from .base import Episode, register_world
from .synthetic import SyntheticParams, SyntheticWorld

__all__ = ["RewardBlocksParams", "RewardBlocksWorld"]

_BLOCK = ParamSpec.sequence(ParamSpec(float), min_length=1)


@dataclass(frozen=True)
class RewardBlocksParams(SyntheticParams):
    """:class:`~.synthetic.SyntheticParams` and the blocks' rewards (``[world]``, ``type = "reward_blocks"``).

    Parameters
    ----------
    contexts, context_names, sources, visit_length, normalise, clock_offsets, frame_shape, nonstationary, learnable, swap, swap_at : object
        The synthetic world's parameters (``SyntheticParams``).
    rewards : tuple, optional
        Must be left None: the blocks set the rewards (a ``ConfigError`` otherwise).
    blocks : tuple of tuple of float, optional
        Per block, the reward of a visit of each context (reward units, one per context); default
        one block paying 1.0 for a visit of each context.
    block_visits : int
        Visits per block, counted over every context from the run's start.
    """

    blocks: tuple | None = spec_param(None, ParamSpec.sequence(_BLOCK, min_length=1, optional=True),
                                      doc="per block, the reward of a visit of each context (reward units); "
                                      "default one block paying 1.0 for each context")
    block_visits: int = param(500, int, low=1, doc="visits per block (over every context)")

    def __post_init__(self):
        super().__post_init__()
        where, n = type(self).__name__, len(self.contexts)
        if self.rewards is not None:
            raise ConfigError(where, "rewards", "no rewards table (the blocks set the rewards)", "a rewards table")
        if self.blocks is None:
            object.__setattr__(self, "blocks", ((1.0,) * n,))
        for k, block in enumerate(self.blocks):
            if len(block) != n:
                raise ConfigError(where, f"blocks[{k}]", f"{n} rewards (one per context)", describe(list(block)))


@register_world("reward_blocks")
class RewardBlocksWorld(SyntheticWorld):
    """The synthetic world whose contexts pay by blocks of visits (module docstring).

    Parameters
    ----------
    params : RewardBlocksParams
        The world's parameters, blocks included: build the world with them (an experiment file's
        ``[world]`` table becomes one).
    contexts, sources, visit_length, normalise, clock_offsets, frame_shape, context_names, nonstationary, learnable, rewards : object
        ``SyntheticWorld``'s keywords: without ``params`` they build a ``RewardBlocksParams`` with the
        default blocks (one block paying 1.0 per visit of each context); ``rewards`` must stay None.
    """

    figures_after_run = True

    Params = RewardBlocksParams

    @classmethod
    def pays_reward(cls, params) -> bool:
        """Whether some block pays a nonzero reward for some context."""
        return any(v != 0 for block in params.blocks for v in block)

    def _reset(self) -> None:
        super()._reset()
        self.visit_count = 0

    def block(self) -> int:
        """The block of the next visit."""
        return min(self.visit_count // self.params.block_visits, len(self.params.blocks) - 1)

    def _paid(self, episode: Episode, n: int = 1) -> Episode:
        """``episode`` paid for its ``n`` visits, each at its own block's reward."""
        reward = 0.0
        for _ in range(n):
            reward += self.params.blocks[self.block()][episode.context]
            self.visit_count += 1
        return dataclasses.replace(episode, reward=float(reward))
