"""A target-detection (vigilance) task for the LC model of Gilzenrat et al. (2002).

Not in the paper. Gilzenrat, Holmes, Rajkowski, Aston-Jones & Cohen (2002, Neural
Networks 15:647) model the monkeys' visual discrimination (vigilance) task of Rajkowski
et al. (1994) and Usher et al. (1999, Science 283:549): stimuli come one per trial, a
rare target among frequent distractors; the animal responds to targets only. Here one
visit is one trial of ``trial_length`` time steps (one frame per Euler step of the model,
:mod:`neurocur.regions.lc_gilzenrat`). A frame holds the input layer of the decision
layer: column 0 the target pathway, column 1 the distractor pathway. From ``onset`` for
``duration`` steps a target gives (1, ``crosstalk``) and a distractor (``crosstalk``, 1);
every other frame is (0, 0). ``crosstalk`` is 0 in ``gilzenrat2002``, whose decision layer
has the crosstalk in its weights. The world draws each trial's stimulus (a target with
probability ``target_probability``); the states are the trial's time steps. One context
("vigilance"): the task has no choice of context.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurocur.config import ConfigError, check_params, param

from .base import Episode, World, register_world
from .rewards import Rewards, check_rewards, rewards_param

__all__ = ["VigilanceParams", "VigilanceWorld"]


@dataclass(frozen=True)
class VigilanceParams:
    """Parameters of :class:`VigilanceWorld` (``[world]`` with ``type = "vigilance"``).

    Parameters
    ----------
    trial_length : int
        Time steps (frames) per trial, at least 2; also the world's number of context-states.
    onset : int
        Time step of the stimulus onset.
    duration : int
        Time steps the stimulus stays on; ``onset + duration`` must not exceed ``trial_length`` (a
        ``ConfigError`` naming ``duration`` otherwise).
    target_probability : float
        Probability in [0, 1] that a trial's stimulus is a target.
    crosstalk : float
        The input in [0, 1] a stimulus gives the other pathway (0 in ``gilzenrat2002``).
    rewards : tuple, optional
        The extrinsic reward of a visit (one entry, the one context; ``neurocur.contexts.rewards``);
        None pays 0.
    """

    trial_length: int = param(200, int, low=2, doc="time steps (frames) per trial")
    onset: int = param(40, int, low=0, doc="time step of the stimulus onset")
    duration: int = param(40, int, low=1, doc="time steps the stimulus stays on")
    target_probability: float = param(0.2, float, low=0.0, high=1.0, doc="probability that a trial's stimulus is a target")
    crosstalk: float = param(0.5, float, low=0.0, high=1.0, doc="input a stimulus gives the other pathway")
    rewards: tuple | None = rewards_param()

    def __post_init__(self):
        check_params(self)
        if self.onset + self.duration > self.trial_length:
            raise ConfigError(type(self).__name__, "duration", f"at most trial_length - onset = "
                              f"{self.trial_length - self.onset}", repr(self.duration))
        check_rewards(self, 1, ("vigilance",))


@register_world("vigilance")
class VigilanceWorld(World):
    """Trials of a target-detection task (module docstring); ``source_names`` = ("target task",).

    Parameters
    ----------
    params : VigilanceParams, optional
        The task's parameters; or give them as keywords instead.
    **kwargs
        The fields of ``VigilanceParams`` as keywords, when ``params`` is not given.
    """

    figures_after_run = True

    Params = VigilanceParams
    frames_conform = True
    frame_shape = (1, 2)
    context_names = ("vigilance",)
    source_names = ("target task",)

    def __init__(self, params: VigilanceParams | None = None, **kwargs) -> None:
        self.params = p = params if params is not None else VigilanceParams(**kwargs)
        self.n_states = self.max_frames = p.trial_length
        self.rewards = Rewards.of(p.rewards)

    def _reset(self) -> None:
        return None

    def _visit(self, context: int) -> Episode:
        p = self.params
        target = bool(self.np_random.random() < p.target_probability)
        frames = np.zeros((p.trial_length, 2))
        frames[p.onset:p.onset + p.duration] = (1.0, p.crosstalk) if target else (p.crosstalk, 1.0)
        return Episode(frames=frames, states=np.arange(p.trial_length, dtype=np.int64), context=context)
