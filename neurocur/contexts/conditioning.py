"""Pavlovian conditioning in trials of time steps: a cue, then a reward after a fixed delay.

Not in the paper. The task of Schultz, Dayan & Montague (1997, Science 275:1593, Fig. 1;
Montague, Dayan & Sejnowski 1996, J Neurosci 16:1936): a conditioned stimulus (the cue) at
time step ``cue``, a reward of size ``reward`` ``delay`` steps later, nothing in between
and nothing the animal does changes it. One visit is one trial of ``trial_length`` time
steps (one frame each; the states are the trial's time steps). A frame has three columns:
0 the cue (1 from its onset for ``cue_duration`` steps), 1 the reward delivered (1 at the
reward step of a rewarded trial) and 2 the experimenter's marker of the time the reward is
due (1 at that step in every trial, delivered or omitted): a model reads columns 0 and 1,
and column 2 only tells a recording where to look. From trial ``omit_after`` on (counted
from 0 in each run), each trial's reward is omitted with probability
``omission_probability`` (probe trials); the episode's ``reward`` is what was delivered.
One context ("conditioning").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurocur.config import ConfigError, check_params, param

from .base import Episode, World, register_world

__all__ = ["ConditioningParams", "ConditioningWorld", "CUE", "DELIVERED", "DUE"]

#: The frame's column of the cue.
CUE = 0
#: The frame's column of the reward delivered.
DELIVERED = 1
#: The frame's column of the time the reward is due (the experimenter's marker).
DUE = 2


@dataclass(frozen=True)
class ConditioningParams:
    """Parameters of :class:`ConditioningWorld` (``[world]`` with ``type = "conditioning"``).

    Parameters
    ----------
    trial_length : int
        Time steps (frames) per trial, at least 2; also the world's number of context-states.
    cue : int
        Time step of the cue's onset, at least 1 (the trial starts with a step without it).
    cue_duration : int
        Time steps the cue stays on (column 0 is 1 from ``cue`` to ``cue + cue_duration - 1``).
    delay : int
        Time steps from the cue's onset to the reward; ``cue + delay`` must be less than
        ``trial_length`` (a ``ConfigError`` naming ``delay`` otherwise).
    reward : float
        Size of the reward (reward units, >= 0): the episode's ``reward`` of a trial that delivers it.
    omit_after : int
        Trials, counted from 0 in each run, before a reward may be omitted (0: from the first trial).
    omission_probability : float
        Probability in [0, 1] that a trial from ``omit_after`` on omits its reward (probe trials).
    """

    trial_length: int = param(25, int, low=2, doc="time steps (frames) per trial")
    cue: int = param(5, int, low=1, doc="time step of the cue's onset (after at least one step without it)")
    cue_duration: int = param(1, int, low=1, doc="time steps the cue stays on")
    delay: int = param(10, int, low=1, doc="time steps from the cue's onset to the reward")
    reward: float = param(1.0, float, low=0.0, doc="size of the reward (reward units)")
    omit_after: int = param(0, int, low=0, doc="trials (from the run's start) before omissions may occur")
    omission_probability: float = param(0.0, float, low=0.0, high=1.0, doc="probability of omitting a trial's reward")

    def __post_init__(self):
        check_params(self)
        if self.cue + self.delay >= self.trial_length:
            raise ConfigError(type(self).__name__, "delay", f"less than trial_length - cue = "
                              f"{self.trial_length - self.cue}", repr(self.delay))


@register_world("conditioning")
class ConditioningWorld(World):
    """Trials of Pavlovian conditioning with a delayed reward (module docstring).

    Parameters
    ----------
    params : ConditioningParams, optional
        The world's parameters; or give them as keywords instead.
    **kwargs
        The fields of ``ConditioningParams`` as keywords, when ``params`` is not given.
    """

    figures_after_run = True

    Params = ConditioningParams
    frames_conform = True
    frame_shape = (1, 3)
    context_names = ("conditioning",)
    source_names = ("cue-reward",)

    @classmethod
    def pays_reward(cls, params) -> bool:
        """Whether some trial delivers its reward: a nonzero ``reward`` not always omitted."""
        return params.reward != 0 and params.omission_probability < 1

    def __init__(self, params: ConditioningParams | None = None, **kwargs) -> None:
        self.params = p = params if params is not None else ConditioningParams(**kwargs)
        self.n_states = self.max_frames = p.trial_length

    def _reset(self) -> None:
        self.trial = 0

    def _visit(self, context: int) -> Episode:
        p = self.params
        omitted = self.trial >= p.omit_after and bool(self.np_random.random() < p.omission_probability)
        self.trial += 1
        frames = np.zeros((p.trial_length, 3))
        frames[p.cue:p.cue + p.cue_duration, CUE] = 1.0
        frames[p.cue + p.delay, DUE] = 1.0
        frames[p.cue + p.delay, DELIVERED] = 0.0 if omitted else 1.0
        return Episode(frames=frames, states=np.arange(p.trial_length, dtype=np.int64), context=context,
                       reward=0.0 if omitted else p.reward)
