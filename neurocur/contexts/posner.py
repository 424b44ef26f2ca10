"""An inferential Posner task with changing cue identity: several cues per trial, one of them relevant.

Not in the paper. The generalised attention task of Yu & Dayan (2005, Neuron 46:681, "A
Generalized Task" and its Fig. 4): on each trial ``cues`` binary cue stimuli are shown
(arrows pointing left, 0, or right, 1, each drawn at random, independently), then a target
appears on the left or the right. One cue, the relevant one (index mu), predicts the
target's side with validity gamma: P(target = c_mu) = gamma, else the target is on the
other side. The relevant cue and its validity stay the same over a block of trials and
change at unsignalled times (nothing in the trial shows the change): the new relevant cue
is drawn uniformly among the other cues, and the new validity is the next one of
``validities`` (cycled). With ``change_probability`` = 0 a block lasts ``block_trials``
trials; otherwise the context changes before each trial with that probability (their
hidden Markov context; the first trial never changes).

One visit is one trial, one frame of ``2 cues + 2`` columns: columns ``0 .. cues - 1`` the
cues, column ``cues`` (:func:`target_column`) the target's side (shown after the cue; a
model uses it only once the trial is over), then the experimenter's markers, which a model
does not read and only a recording does: one-hot the relevant cue
(:func:`relevant_columns`) and its validity (:func:`validity_column`). One context ("posner").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurocur.config import ParamSpec, check_params, param, spec_param

from .base import Episode, World, register_world

__all__ = ["PosnerParams", "PosnerWorld", "cues_of", "relevant_columns", "target_column", "validity_column"]

_VALIDITY = ParamSpec(float, low=0.5, high=1.0)


def cues_of(world, reader: str) -> int:
    """The number of cues of ``world``'s frames, for the region ``reader`` that binds to it; a
    ``ValueError`` naming the reader when the world's frames are not a posner world's.

    Parameters
    ----------
    world : World
        The world the region binds to.
    reader : str
        The region's name, for the message.

    Returns
    -------
    int
        The number of cues, ``(width - 2) // 2`` of the frame's ``width`` columns.
    """
    width = world.frame_shape[-1]
    if not isinstance(world, PosnerWorld) or width < 6 or width % 2:
        raise ValueError(f"{reader}: needs the frames of a posner world (2 cues + 2 columns); the world is "
                         f"{type(world).__name__} with {width} columns")
    return (width - 2) // 2


def target_column(cues: int) -> int:
    """The column of the target's side (0 left, 1 right) in a frame of a world with ``cues`` cues.

    Parameters
    ----------
    cues : int
        The number of cues per trial.

    Returns
    -------
    int
        The column index, ``cues``.
    """
    return cues


def relevant_columns(cues: int) -> slice:
    """The columns of the one-hot marker of the relevant cue (not for the model).

    Parameters
    ----------
    cues : int
        The number of cues per trial.

    Returns
    -------
    slice
        Columns ``cues + 1`` to ``2 cues``: column ``cues + 1 + mu`` is 1 for the relevant cue ``mu``.
    """
    return slice(cues + 1, 2 * cues + 1)


def validity_column(cues: int) -> int:
    """The column of the marker of the relevant cue's validity gamma (not for the model).

    Parameters
    ----------
    cues : int
        The number of cues per trial.

    Returns
    -------
    int
        The column index, ``2 cues + 1`` (the frame's last).
    """
    return 2 * cues + 1


@dataclass(frozen=True)
class PosnerParams:
    """Parameters of :class:`PosnerWorld` (``[world]`` with ``type = "posner"``).

    Parameters
    ----------
    cues : int
        h, the cue stimuli per trial (at least 2).
    validities : tuple of float
        The relevant cue's validity gamma in successive blocks, cycled; each in [0.5, 1].
    block_trials : int
        Trials per block when ``change_probability`` is 0.
    change_probability : float
        Probability in [0, 1) that the context (relevant cue and validity) changes before a trial,
        the first excepted; 0: a change every ``block_trials`` trials.
    """

    cues: int = param(5, int, low=2, doc="h, cue stimuli per trial")
    validities: tuple = spec_param((0.95, 0.65, 0.85, 0.75), ParamSpec.sequence(_VALIDITY, min_length=1),
                                   doc="the relevant cue's validity gamma in successive blocks (cycled), each in [0.5, 1]")
    block_trials: int = param(250, int, low=1, doc="trials per block when change_probability is 0")
    change_probability: float = param(0.0, float, low=0.0, high=1.0, high_open=True,
                                      doc="probability that the context changes before a trial (0: every block_trials trials)")

    def __post_init__(self):
        check_params(self)


@register_world("posner")
class PosnerWorld(World):
    """Trials of the inferential Posner task with changing cue identity (module docstring).

    Parameters
    ----------
    params : PosnerParams, optional
        The task's parameters; or give them as keywords instead.
    **kwargs
        The fields of ``PosnerParams`` as keywords, when ``params`` is not given.
    """

    figures_after_run = True

    Params = PosnerParams
    frames_conform = True
    context_names = ("posner",)
    source_names = ("cue-target",)

    @classmethod
    def pays_reward(cls, params) -> bool:
        """Never: the task's feedback is the target's side, not a reward."""
        return False

    def __init__(self, params: PosnerParams | None = None, **kwargs) -> None:
        self.params = p = params if params is not None else PosnerParams(**kwargs)
        self.frame_shape = (1, 2 * p.cues + 2)
        self.n_states = self.max_frames = 1

    def _reset(self) -> None:
        self.trial = 0
        self.block = 0
        self.relevant = int(self.np_random.integers(self.params.cues))

    def _changes(self) -> bool:
        p = self.params
        if self.trial == 0:
            return False
        if p.change_probability > 0:
            return bool(self.np_random.random() < p.change_probability)
        return self.trial % p.block_trials == 0

    def _visit(self, context: int) -> Episode:
        p, rng = self.params, self.np_random
        if self._changes():
            self.block += 1
            self.relevant = (self.relevant + 1 + int(rng.integers(p.cues - 1))) % p.cues
        self.trial += 1
        validity = p.validities[self.block % len(p.validities)]
        cues = (rng.random(p.cues) < 0.5).astype(float)
        cued = cues[self.relevant]
        target = cued if rng.random() < validity else 1.0 - cued
        frame = np.zeros((1, 2 * p.cues + 2))
        frame[0, :p.cues] = cues
        frame[0, target_column(p.cues)] = target
        frame[0, p.cues + 1 + self.relevant] = 1.0
        frame[0, validity_column(p.cues)] = validity
        return Episode(frames=frame, states=np.zeros(1, dtype=np.int64), context=context)
