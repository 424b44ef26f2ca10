"""Choosing what to learn: the utilities of Ten et al. 2021's choice models (docs/ten2021.md).

Ten, Kaushik, Oudeyer & Gottlieb (2021), "Humans monitor learning progress in curiosity-driven
exploration", *Nature Communications* 12:5977; the definitions are those of the authors'
published analysis code (Zenodo 10.5281/zenodo.5068243, ``prepare_data.ipynb`` and
``python_scripts/utils/model_utils.py``). Each activity k (one option of the world of options)
has, before each trial's choice and from the outcomes of its earlier trials (forced and free):

- ``plays``: how many times it was played (the code's ``abst``, time);
- ``pc``: competence, the percent correct over its last ``window`` = 15 trials;
- ``lp``: learning progress, |PC over the last ``late`` = 9 of those 15 − PC over the first
  ``early`` = 10| (:func:`window_signals`); NaN while fewer than 15 trials are known.

``ten2021.utility`` (a PFC role) emits the utilities U_k = Σ_i c_i x̃_{i,k} with c_i = τ w_i the
products the paper's softmax exp(τ Σ w_i x̃_i) identifies, x̃ each signal rescaled per
participant to [0, 1] by min-max over the session's scored trials, every activity together
(:func:`minmax`; the paper's ``normalize``). The choice is ``bandit.softmax`` with β = 1 and its
perseveration κ: P(k) = softmax_k(U_k + κ [k = previous choice]).

**The session.** A session starts with the forced phase: ``window`` trials of each activity in
blocks (the paper's 60 trials, 4 blocks of 15 in an order drawn per participant). Its choices are
given, not chosen: the region emits utility 0 for the imposed activity and −inf for the others, so
the softmax gives it probability 1 and a replay scores it log 1 = 0. In a replay of recorded trials
(:attr:`~neurocur.contexts.options.OptionsWorld.session`) the imposed activity is the recorded one,
and so are the first ``unscored`` free choices (1: the paper does not score the first free choice);
the rescaling uses the range of each signal over the scored trials of the whole session, which is
known only afterwards (not causal: the paper's definition). A live simulation draws the block order
and needs ``rescale = false`` and ``unscored = 0`` (raw signals, every free choice scored).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register

__all__ = ["EARLY", "LATE", "SIGNALS", "WINDOW", "activity_signals", "minmax", "window_signals"]

#: Trials of an activity in its competence window (the paper's 15); also the forced block's length.
WINDOW = 15
#: The first part of the window that learning progress compares (10 trials)...
EARLY = 10
#: ... with its last part (9 trials).
LATE = 9
#: The signals, in the order of :class:`UtilityParams`' weights.
SIGNALS = ("pc", "lp", "plays")


def window_signals(past, *, window: int = WINDOW, early: int = EARLY, late: int = LATE) -> tuple[float, float]:
    """``(pc, lp)`` of one activity from its outcomes so far (``past``, oldest first): the mean of the last
    ``window`` and |mean of their last ``late`` − mean of their first ``early``|; NaN, NaN while fewer
    than ``window`` are known.

    Parameters
    ----------
    past : sequence of float
        The activity's outcomes so far, oldest first (1 correct, 0 not, or a score in [0, 1]).
    window : int
        Trials in the competence window (the paper's 15).
    early : int
        The window's first trials that learning progress compares (10).
    late : int
        The window's last trials it compares them with (9).

    Returns
    -------
    pc : float
        Percent correct (as a fraction) over the last ``window`` outcomes; NaN while fewer are known.
    lp : float
        Learning progress, the absolute difference of the two means; NaN while fewer are known.
    """
    if len(past) < window:
        return np.nan, np.nan
    recent = [float(o) for o in past[-window:]]  # plain sums: exact for 0/1 outcomes, and fast per trial
    return sum(recent) / window, abs(sum(recent[-late:]) / late - sum(recent[:early]) / early)


def activity_signals(choices, outcomes, n_activities: int = 4, *, window: int = WINDOW, early: int = EARLY,
                     late: int = LATE) -> dict[str, np.ndarray]:
    """``{"plays", "pc", "lp"}``, each of shape ``(trials, n_activities)``: row *t* holds the
    signals before the choice of trial *t* (from trials ``0 .. t-1``, :func:`window_signals`).
    ``choices``: the activity of each trial, 0-based; ``outcomes``: 1 correct, 0 not (or a score in [0, 1]).

    Parameters
    ----------
    choices : array of int
        The activity of each trial, 0-based, below ``n_activities``.
    outcomes : array of float
        The outcome of each trial, in [0, 1] (1 correct, 0 not); the same length as ``choices``.
    n_activities : int
        The number of activities (4 in the paper).
    window : int
        Trials in the competence window (15).
    early : int
        The window's first trials that learning progress compares (10), in ``1 .. window``.
    late : int
        The window's last trials it compares them with (9), in ``1 .. window``.

    Returns
    -------
    dict of str to array
        ``"plays"`` (int64), ``"pc"`` and ``"lp"`` (float64, NaN while fewer than ``window`` trials of
        the activity are known), each of shape ``(trials, n_activities)``.

    Raises
    ------
    ValueError
        Choices and outcomes of different lengths, choices that are not integers in
        ``0 .. n_activities - 1``, outcomes outside [0, 1] or NaN, or ``early``/``late`` outside
        ``1 .. window``.
    """
    choices = np.asarray(choices)
    outcomes = np.asarray(outcomes, dtype=float)
    if choices.ndim != 1 or choices.shape != outcomes.shape:
        raise ValueError(f"activity_signals expected choices and outcomes of the same length, got shapes "
                         f"{choices.shape} and {outcomes.shape}")
    if not np.issubdtype(choices.dtype, np.integer) or ((choices < 0) | (choices >= n_activities)).any():
        raise ValueError(f"activity_signals expected choices as integers 0 .. {n_activities - 1}, got {choices!r}")
    if np.isnan(outcomes).any() or ((outcomes < 0) | (outcomes > 1)).any():
        raise ValueError("activity_signals expected outcomes between 0 and 1")
    if not (1 <= early <= window and 1 <= late <= window):
        raise ValueError(f"activity_signals expected 1 <= early, late <= window, got early={early}, late={late}, "
                         f"window={window}")
    n = len(choices)
    plays = np.zeros((n, n_activities), dtype=np.int64)
    pc = np.full((n, n_activities), np.nan)
    lp = np.full((n, n_activities), np.nan)
    history: list[list[float]] = [[] for _ in range(n_activities)]
    for t in range(n):
        for k, past in enumerate(history):
            plays[t, k] = len(past)
            pc[t, k], lp[t, k] = window_signals(past, window=window, early=early, late=late)
        history[choices[t]].append(outcomes[t])
    return {"plays": plays, "pc": pc, "lp": lp}


def minmax(values) -> np.ndarray:
    """``(x - min) / (max - min)`` over every finite value of ``values`` (NaN stays NaN). A
    constant signal becomes 0 everywhere: a constant added to every activity's utility leaves the
    softmax unchanged, so any constant is exact.

    Parameters
    ----------
    values : array_like of float
        The signal, any shape (e.g. ``(trials, n_activities)``), NaN where undefined.

    Returns
    -------
    array of float64
        The rescaled values in [0, 1], the shape of ``values``.
    """
    x = np.asarray(values, dtype=float)
    low, span = _range(x)
    return np.where(np.isfinite(x), (x - low) / span if span > 0 else 0.0, np.nan)


def _range(x: np.ndarray) -> tuple[float, float]:
    """(min, max - min) of the finite values of ``x`` (NaN, NaN when there are none)."""
    finite = x[np.isfinite(x)]
    if finite.size == 0:
        return np.nan, np.nan
    return float(finite.min()), float(finite.max() - finite.min())


@functools.lru_cache(maxsize=64)
def session_signals(choices: bytes, outcomes: bytes, n_activities: int, first: int):
    """A recorded session's signals, ``(3, trials, n_activities)`` in the order of :data:`SIGNALS`
    (:func:`activity_signals`), and each signal's min and max - min over the trials from ``first`` on
    (a constant signal's span is inf: its rescaled value is 0). ``choices`` int64 and ``outcomes``
    float64 as bytes: the many fresh regions of one replay compute them once."""
    signals = activity_signals(np.frombuffer(choices, dtype=np.int64), np.frombuffer(outcomes, dtype=np.float64),
                               n_activities)
    x = np.stack([signals[name].astype(float) for name in SIGNALS])
    ranges = np.array([_range(x[i, first:]) for i in range(len(SIGNALS))])
    ranges[ranges[:, 1] == 0, 1] = np.inf
    for array in (x, ranges):
        array.flags.writeable = False
    return x, ranges[:, 0], ranges[:, 1]


@dataclass(frozen=True)
class UtilityParams:
    pc: float = param(0.0, float, low=-100.0, high=100.0, doc="c_PC = tau w_PC, the weight of (rescaled) "
                      "competence in the utility")
    lp: float = param(0.0, float, low=-100.0, high=100.0, doc="c_LP = tau w_LP, the weight of (rescaled) "
                      "learning progress")
    plays: float = param(0.0, float, low=-100.0, high=100.0, doc="c_TIME = tau w_TIME, the weight of the "
                         "(rescaled) number of plays")
    rescale: bool = param(True, bool, doc="rescale each signal to [0, 1] by its range over the replayed "
                          "session's scored trials (the paper's; a live simulation needs false)")
    unscored: int = param(1, int, low=0, doc="free choices at the start of a replayed session given, not "
                          "scored (the paper's 1; a live simulation needs 0)")

    def __post_init__(self):
        check_params(self)


@register("ten2021.utility")
class ActivityUtility(Region):
    """Each activity's utility before this trial's choice (module docstring): Σ_i c_i x̃_{i,k} on a
    free trial, 0 for the imposed activity and −inf for the others on a forced (or unscored) trial.
    Learns the previous trial's outcome first (delayed inputs), as ``bandit.delta`` does."""

    Params = UtilityParams
    inputs = (
        Signal("chosen", "int64", (), "the activity chosen at the previous trial (None before the first)"),
        Signal("outcome", "float64", (), "the outcome of that choice (1 correct, 0 not)"),
    )
    outputs = (Signal("values", "float64", ("n_contexts",), "each activity's utility before this trial's choice"),)
    probes = (Probe("given", "int", "flag", "1 when this trial's activity was imposed (forced phase, or a free "
                    "choice the replay does not score), 0 when chosen"),)

    def bind(self, world) -> None:
        self.n_options = n = world.n_contexts
        self.forced = WINDOW * n
        self.low, self.span = np.zeros(3), np.ones(3)
        session = getattr(world, "session", None)
        p = self.params
        if session is None:
            if p.rescale or p.unscored:
                raise ValueError(f"{self.name}: ten2021.utility with rescale = {str(p.rescale).lower()} and "
                                 f"unscored = {p.unscored} needs a recorded session (a replay of trials): the "
                                 "paper's rescaling uses the whole session; simulate with rescale = false and "
                                 "unscored = 0")
            self.session, self.table = None, None
            return
        choices, outcomes = session
        counts = np.bincount(choices[:self.forced], minlength=n)
        if len(choices) <= self.forced + p.unscored or not (counts == WINDOW).all():
            raise ValueError(f"{self.name}: ten2021.utility expected a session starting with the forced phase "
                             f"({WINDOW} trials of each of the {n} activities) and at least one scored free choice "
                             f"after {p.unscored} unscored, got {len(choices)} trials with {counts.tolist()} of "
                             f"each activity in the first {self.forced}")
        self.session = choices
        self.table, low, span = session_signals(choices.tobytes(), outcomes.tobytes(), n, self.forced + p.unscored)
        if p.rescale:
            self.low, self.span = low, span

    def reset(self, rng) -> None:
        n, p = self.n_options, self.params
        self.order = rng.permutation(n) if self.session is None else None
        self.history: list[list[float]] = [[] for _ in range(n)]
        self.x = np.zeros((3, n))
        self.x[:2] = np.nan
        self.t, self.given = 0, 1
        weights = np.array([p.pc, p.lp, p.plays])
        self.used = np.flatnonzero(weights)
        self.coef = weights[self.used] / self.span[self.used]
        self.given_rows = np.where(np.eye(n, dtype=bool), 0.0, -np.inf)

    def imposed(self, t: int) -> int | None:
        """The activity imposed at trial ``t`` (forced, or a given free choice of a replay), or None."""
        if t < self.forced:
            return int(self.order[t // WINDOW]) if self.session is None else int(self.session[t])
        if self.session is not None and t < self.forced + self.params.unscored:
            return int(self.session[t])
        return None

    def step(self, chosen, outcome):
        t, self.t = self.t, self.t + 1
        if self.session is not None:  # a replay: the session's signals, row t from trials 0 .. t-1
            x = self.table[:, t]
        else:
            if chosen is not None:
                past = self.history[chosen]
                past.append(float(outcome))
                self.x[0, chosen], self.x[1, chosen] = window_signals(past)
                self.x[2, chosen] = len(past)
            x = self.x
        k = self.imposed(t)
        self.given = int(k is not None)
        if k is not None:
            return (self.given_rows[k].copy(),)
        if not len(self.used):
            return (np.zeros(self.n_options),)
        return (self.coef @ (x[self.used] - self.low[self.used, None]),)

    def record(self):
        return (self.given,)
