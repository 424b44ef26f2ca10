"""The activity signals of Ten et al. 2021's choice models, as small numpy functions (docs/ten2021.md).

For one participant's whole sequence of trials (forced, then free), each trial's signals of every
activity *before* that trial's choice, from the outcomes of the earlier trials of the activity:

- ``plays``: how many times the activity was played (the paper's code calls it ``abst``, time);
- ``pc``: competence, the percent correct over the activity's last ``window`` = 15 trials;
- ``lp``: learning progress, the absolute difference between the percent correct over the last
  ``late`` = 9 and over the first ``early`` = 10 of those 15 trials (the two parts overlap by 4);

NaN while the activity has fewer than ``window`` trials. The forced phase plays each activity 15
times, so every window is full when free play begins and the first free choice already sees the
forced trials' PC and LP. These are the quantities of the authors' published analysis code
(Zenodo 10.5281/zenodo.5068243, ``prepare_data.ipynb``: 15-trial rolling windows per activity,
carried forward between the activity's trials, LP by ``rlp_func``, absolute).

:func:`minmax` is the per-participant rescaling the paper's fits apply to each signal before the
softmax (``model_utils.normalize``): all of a participant's values of the signal, every activity
and trial together, mapped onto [0, 1].
"""

from __future__ import annotations

import numpy as np

__all__ = ["EARLY", "LATE", "WINDOW", "activity_signals", "minmax"]

#: Trials of an activity in its competence window (the paper's 15).
WINDOW = 15
#: The first part of the window that learning progress compares (10 trials)...
EARLY = 10
#: ... with its last part (9 trials).
LATE = 9


def activity_signals(choices, outcomes, n_activities: int = 4, *, window: int = WINDOW, early: int = EARLY,
                     late: int = LATE) -> dict[str, np.ndarray]:
    """``{"plays", "pc", "lp"}``, each of shape ``(trials, n_activities)``: row *t* holds the
    signals before the choice of trial *t* (from trials ``0 .. t-1``). ``choices``: the activity
    of each trial, 0-based; ``outcomes``: 1 correct, 0 not (or a score in [0, 1])."""
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
            if len(past) >= window:
                recent = np.asarray(past[-window:])
                pc[t, k] = recent.mean()
                lp[t, k] = abs(recent[-late:].mean() - recent[:early].mean())
        history[choices[t]].append(outcomes[t])
    return {"plays": plays, "pc": pc, "lp": lp}


def minmax(values) -> np.ndarray:
    """``(x - min) / (max - min)`` over every finite value of ``values`` (NaN stays NaN). A
    constant signal becomes 0 everywhere: a constant added to every activity's utility leaves the
    softmax unchanged, so any constant is exact."""
    x = np.asarray(values, dtype=float)
    finite = x[np.isfinite(x)]
    if finite.size == 0:
        return np.full_like(x, np.nan)
    low, span = finite.min(), finite.max() - finite.min()
    return np.where(np.isfinite(x), (x - low) / span if span > 0 else 0.0, np.nan)
