"""A world of options, each paying an outcome when chosen: the world of a bandit task.

Each context is an option (a slot machine's arm, a stimulus); a visit is one trial, one
blank frame, and pays a Bernoulli outcome: 1 with the option's probability ``p_reward``, else
0 (a stationary multi-armed bandit, Sutton & Barto 2018, chapter 2; hBayesDM's
``bandit2arm_delta``). The draw comes from the world's generator, one uniform per visit.

The same world replays recorded trials (:meth:`OptionsWorld.recorded`): visit t pays the
recorded outcome of trial t, and a visit of another option than the recorded choice is an
error, so a replayed circuit learns from the outcomes people saw. The task region
``bandit.task`` (:mod:`neurocur.regions.bandit`) starts a run with :meth:`OptionsWorld.begin`,
which visits nothing (a trial's option is the decision's, made in the same pass).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurocur.config import ConfigError, ParamSpec, check_params, describe, spec_param

from .base import Episode, World, register_world

__all__ = ["OptionsParams", "OptionsWorld"]


@dataclass(frozen=True)
class OptionsParams:
    """Parameters of :class:`OptionsWorld` (``[world] type = "options"``).

    Parameters
    ----------
    options : tuple of str
        The options' distinct names, in index order (at least two); option ``i`` is context ``i``.
    p_reward : tuple of float
        Per option, the probability in [0, 1] that a visit pays 1 (else 0); one per option.
    """

    options: tuple[str, ...] = spec_param(("A", "B"), ParamSpec.sequence(ParamSpec(str), min_length=2),
                                          doc="the options' names (distinct), in index order")
    p_reward: tuple[float, ...] = spec_param((0.7, 0.3), ParamSpec.sequence(ParamSpec(float, low=0.0, high=1.0),
                                                                            min_length=2),
                                             doc="probability that each option pays 1 (else 0)")

    def __post_init__(self):
        check_params(self)
        if len(set(self.options)) != len(self.options):
            raise ConfigError("OptionsParams", "options", "distinct names", describe(list(self.options)))
        if len(self.p_reward) != len(self.options):
            raise ConfigError("OptionsParams", "p_reward", f"{len(self.options)} probabilities (one per option: "
                              f"{', '.join(self.options)})", describe(list(self.p_reward)))


@register_world("options")
class OptionsWorld(World):
    """Options paying Bernoulli outcomes (module docstring); ``recorded`` (choices, outcomes) replays trials.

    Parameters
    ----------
    params : OptionsParams, optional
        The options and their reward probabilities (default: ``OptionsParams()``, two options A and
        B paying with probabilities 0.7 and 0.3).
    """

    Params = OptionsParams
    n_states = 1
    frame_shape = (1, 1)
    max_frames = 1
    frames_conform = True

    def __init__(self, params: OptionsParams | None = None):
        self.params = params if params is not None else OptionsParams()
        self.context_names = tuple(self.params.options)
        self.source_names = self.context_names
        self._recorded = None
        self._trial = 0

    def recorded(self, choices, outcomes) -> OptionsWorld:
        """This world replaying trials: visit t pays ``outcomes[t]`` and must be of option ``choices[t]``."""
        world = OptionsWorld(self.params)
        world._recorded = (np.asarray(choices, dtype=np.int64), np.asarray(outcomes, dtype=np.float64))
        return world

    @property
    def session(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The recorded trials this world replays, ``(choices, outcomes)`` (copies), or None for a world
        that draws its outcomes: a model that uses the whole session (Ten et al. 2021's rescaling,
        :mod:`neurocur.regions.ten2021`) reads it here."""
        if self._recorded is None:
            return None
        return self._recorded[0].copy(), self._recorded[1].copy()

    def begin(self) -> None:
        """Start a run without visiting an option (the next visit is trial 0)."""
        self._trial = 0

    def _reset(self) -> None:
        self.begin()

    def _visit(self, context: int) -> Episode:
        t = self._trial
        if self._recorded is None:
            outcome = float(self.np_random.random() < self.params.p_reward[context])
        else:
            choices, outcomes = self._recorded
            if t >= len(choices) or choices[t] != context:
                expected = f"option {choices[t]}" if t < len(choices) else f"at most {len(choices)} trials"
                raise ValueError(f"recorded trials: expected {expected} at trial {t}, got a visit of option {context}")
            outcome = float(outcomes[t])
        self._trial = t + 1
        return Episode(frames=np.zeros((1, 1)), states=np.zeros(1, dtype=np.int64), context=int(context),
                       reward=outcome)
