"""Ten et al. 2021's choice models as vectorised likelihoods, and a simulator of the study's design.

The experiment ``ten2021``'s conditions (docs/ten2021.md) are softmax choices whose logits are
linear in their parameters: on each scored free choice, activity k's logit is

    z_k = c_PC x̃_PC,k + c_LP x̃_LP,k + c_TIME x̃_TIME,k + κ [k = previous choice],

x̃ each signal rescaled per participant over the scored trials (``neurocur.regions.ten2021``:
the same :func:`~neurocur.regions.ten2021.session_signals`). A session's features are computed
once (:func:`session_features`), after which any number of parameter vectors costs one product:
:class:`Session` gives :func:`~neurocur.fit.hierarchical.fit_hierarchical` and
:func:`~neurocur.fit.mle.fit_ml` the log-likelihood of the 249 scored choices in a vectorised
:class:`~neurocur.fit.hierarchical.Subject` (a test checks it against the circuit's replay to 1e-9).

:func:`simulate_sessions` plays many sessions at once on the study's design (Ten et al. 2021,
Fig. 1: 15 forced trials of each activity in blocks of a random order, then free choices), with
the raw signals a live agent has (the circuit's ``PFC.rescale = false``, ``PFC.unscored = 0``) and
each activity's chance of a correct answer given per play (a fixed percent correct, or a learning
curve). Weights fitted on rescaled signals map to raw ones through the participant's own range,
c / span (:func:`raw_coefficients`): the rescaling is affine, so the utilities differ by a constant
the softmax ignores.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import special

from ..config import ConfigError
from ..experiments import load_experiment
from ..regions.ten2021 import EARLY, LATE, SIGNALS, WINDOW, session_signals
from .hierarchical import MAX_ITER, N_SAMPLES, Subject, fit_hierarchical
from .mle import fit_ml
from .study import default_bounds

__all__ = ["FEATURES", "KEYS", "LP_MODELS", "MODELS", "MODEL_SETS", "Session", "coefficients", "fit_group", "model_bounds",
           "raw_coefficients", "session_features", "simulate_sessions"]

#: The features of the logits: the three signals of ``ten2021.utility`` and the repetition of the previous choice.
FEATURES = (*SIGNALS, "repeat")
#: The experiment's parameter of each feature's coefficient.
KEYS = {"PFC.pc": "pc", "PFC.lp": "lp", "PFC.plays": "plays", "LC.kappa": "repeat"}
#: Free choices at the start of free play that are given, not scored (the paper's 1).
UNSCORED = 1
#: The conditions of the experiment ten2021 compared in hypothesis run 17 (docs/ten2021.md).
MODELS = ("random", "perseveration", "pc", "lp", "pc_lp", "pc_lp_time")
#: The models with a learning-progress component.
LP_MODELS = ("lp", "pc_lp", "pc_lp_time")
#: The sets of models a comparison fits (``--models``): each set's models and its models with a learning-progress
#: component; ``paper`` is hypothesis run 17's, ``persev`` run 19's (the utilities with perseveration beside them),
#: ``time`` run 20's (perseveration + PC + TIME, with and without LP).
MODEL_SETS = {
    "paper": (MODELS, LP_MODELS),
    "persev": (("perseveration", "persev_pc", "persev_lp", "persev_pc_lp", "persev_pc_lp_time"),
               ("persev_lp", "persev_pc_lp", "persev_pc_lp_time")),
    "time": (("persev_pc_time", "persev_pc_lp_time"), ("persev_pc_lp_time",)),
}


@dataclass(frozen=True)
class Session:
    """One participant's scored choices: ``features`` (len(FEATURES), n, activities), the signals rescaled
    to [0, 1] over the scored trials and the repetition indicator; ``chosen`` (n,); each signal's ``low``
    and ``span`` over those trials (span inf for a constant signal, whose rescaled value is 0).

    Parameters
    ----------
    name : str
        The participant (the subject's name in the fits' tables).
    features : numpy.ndarray
        (len(FEATURES), n, activities): per feature, scored choice and activity, the rescaled signal (pc, lp,
        plays) or the repetition indicator (1 for the previous choice's activity).
    chosen : numpy.ndarray
        (n,) the activity chosen on each scored choice (0-based).
    low : numpy.ndarray
        (len(SIGNALS),) each signal's minimum over the scored trials.
    span : numpy.ndarray
        (len(SIGNALS),) each signal's range over the scored trials (inf for a constant signal).
    """

    name: str
    features: np.ndarray
    chosen: np.ndarray
    low: np.ndarray
    span: np.ndarray

    @property
    def n_obs(self) -> int:
        return len(self.chosen)

    def logp(self, coefs) -> np.ndarray:
        """(m, n) log-probabilities of the scored choices for m coefficient vectors (m, len(FEATURES))."""
        coefs = np.atleast_2d(np.asarray(coefs, dtype=np.float64))
        z = np.einsum("mf,fnk->mnk", coefs, self.features)
        return np.take_along_axis(special.log_softmax(z, axis=2), self.chosen[None, :, None], axis=2)[..., 0]

    def subject(self, keys: Sequence[str]) -> Subject:
        """The vectorised :class:`~neurocur.fit.hierarchical.Subject` of the model fitting ``keys`` (experiment
        keys, :data:`KEYS`), the other coefficients 0."""
        unknown = [key for key in keys if key not in KEYS]
        if unknown:
            raise ConfigError("ten2021", unknown[0], f"one of {', '.join(KEYS)}", repr(unknown[0]))
        columns = [FEATURES.index(KEYS[key]) for key in keys]

        def loglik(points):
            coefs = np.zeros((len(points), len(FEATURES)))
            coefs[:, columns] = points
            return self.logp(coefs).sum(axis=1)
        return Subject(loglik, self.n_obs, keys, vectorised=True)


def session_features(choices, outcomes, *, n_activities: int = 4, name: str = "session",
                     unscored: int = UNSCORED) -> Session:
    """The :class:`Session` of one recorded session (activity indices, 0/1 outcomes) that starts with the forced
    phase (``WINDOW`` trials of each activity): its choices after the forced phase and ``unscored`` free ones.

    Parameters
    ----------
    choices : array of int
        The session's activity on each trial, forced and free, in order (0-based).
    outcomes : array of float
        Each trial's outcome, 1 correct and 0 not.
    n_activities : int
        The activities.
    name : str
        The participant, named in the :class:`Session` and in the error.
    unscored : int
        Free choices at the start of free play that are given, not scored (the paper's 1).

    Returns
    -------
    Session
        The features of the choices after the forced phase and the ``unscored`` free ones.

    Raises
    ------
    ConfigError
        Unless the session starts with ``WINDOW`` forced trials of each activity and has a scored free choice.
    """
    choices = np.ascontiguousarray(choices, dtype=np.int64)
    outcomes = np.ascontiguousarray(outcomes, dtype=np.float64)
    forced = WINDOW * n_activities
    first = forced + unscored
    counts = np.bincount(choices[:forced], minlength=n_activities)
    if len(choices) <= first or not (counts == WINDOW).all():
        raise ConfigError(name, "choice", f"a session starting with {WINDOW} forced trials of each of the {n_activities} "
                          f"activities and at least one scored free choice", f"{len(choices)} trials with "
                          f"{counts.tolist()} of each activity in the first {forced}")
    x, low, span = session_signals(choices.tobytes(), outcomes.tobytes(), n_activities, first)
    rows = np.arange(first, len(choices))
    features = np.zeros((len(FEATURES), len(rows), n_activities))
    features[:len(SIGNALS)] = (x[:, rows] - low[:, None, None]) / span[:, None, None]
    features[len(SIGNALS)] = choices[rows - 1][:, None] == np.arange(n_activities)
    return Session(name, features, choices[rows], np.asarray(low), np.asarray(span))


def raw_coefficients(coefs, span) -> np.ndarray:
    """Coefficients of the rescaled signals (..., len(FEATURES)) as coefficients of the raw ones: c / span for
    the signals (0 for a constant one, span inf), the repetition's unchanged.

    Parameters
    ----------
    coefs : array_like
        (..., len(FEATURES)) coefficients of the rescaled signals and of the repetition.
    span : array_like
        Each signal's range over the scored trials (:attr:`Session.span`), broadcast against ``coefs``'
        signal columns ((len(SIGNALS),) for one participant, (S, len(SIGNALS)) for S).

    Returns
    -------
    numpy.ndarray
        The coefficients of the raw signals, in ``coefs``' shape (a copy).
    """
    coefs = np.array(coefs, dtype=np.float64)
    coefs[..., :len(SIGNALS)] = coefs[..., :len(SIGNALS)] / np.asarray(span, dtype=np.float64)
    return coefs


def simulate_sessions(rng: np.random.Generator, coefs, p_correct, *, n_free: int = 250,
                      n_activities: int = 4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sessions of the study's design played at once: ``coefs`` (S, len(FEATURES)), raw-signal coefficients
    (:func:`raw_coefficients`) of session s; ``p_correct`` the chance of a correct answer of each activity,
    (activities,) fixed or (activities, plays) by the activity's play number (0-based; the last column beyond).
    Each session draws the order of its forced blocks, then chooses ``n_free`` times by the softmax of
    :class:`Session`'s logits on the raw signals (every free choice scored). Returns ``choices``, ``outcomes``
    and ``logp`` (S, 60 + n_free): the log-probability of each choice as drawn (0 on a forced trial).

    Parameters
    ----------
    rng : numpy.random.Generator
        The draws: the forced blocks' orders, the free choices and the outcomes.
    coefs : array_like
        (S, len(FEATURES)) raw-signal coefficients, a session each.
    p_correct : array_like
        The chance of a correct answer of each activity, in [0, 1]: (activities,) fixed, or
        (activities, plays) by the activity's play number.
    n_free : int
        Free choices after the forced phase.
    n_activities : int
        The activities.

    Returns
    -------
    tuple of (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        ``choices`` (int), ``outcomes`` (0/1) and ``logp``, each (S, ``WINDOW`` x ``n_activities`` + ``n_free``).

    Raises
    ------
    ValueError
        When ``coefs`` has not len(FEATURES) columns, or ``p_correct`` has not a row per activity in [0, 1].
    """
    coefs = np.atleast_2d(np.asarray(coefs, dtype=np.float64))
    p = np.asarray(p_correct, dtype=np.float64)
    p = p[:, None] if p.ndim == 1 else p
    if coefs.shape[1] != len(FEATURES) or p.shape[0] != n_activities or not ((p >= 0) & (p <= 1)).all():
        raise ValueError(f"simulate_sessions expected coefs (S, {len(FEATURES)}) and p_correct in [0, 1] with "
                         f"{n_activities} rows, got {coefs.shape} and {p.shape}")
    n_sessions, forced = len(coefs), WINDOW * n_activities
    n_trials = forced + n_free
    order = np.argsort(rng.random((n_sessions, n_activities)), axis=1)
    history = np.zeros((n_sessions, n_activities, n_trials))
    plays = np.zeros((n_sessions, n_activities), dtype=np.int64)
    choices = np.zeros((n_sessions, n_trials), dtype=np.int64)
    outcomes = np.zeros((n_sessions, n_trials))
    logp = np.zeros((n_sessions, n_trials))
    rows, last = np.arange(n_sessions), np.arange(WINDOW)
    for t in range(n_trials):
        if t < forced:
            k = order[:, t // WINDOW]
        else:
            window = np.take_along_axis(history, (plays - WINDOW)[..., None] + last, axis=2)
            pc = window.mean(axis=2)
            lp = np.abs(window[..., -LATE:].mean(axis=2) - window[..., :EARLY].mean(axis=2))
            repeat = choices[:, t - 1, None] == np.arange(n_activities)
            z = coefs[:, :1] * pc + coefs[:, 1:2] * lp + coefs[:, 2:3] * plays + coefs[:, 3:4] * repeat
            log_prob = special.log_softmax(z, axis=1)
            k = (np.cumsum(np.exp(log_prob), axis=1) < rng.random((n_sessions, 1))).sum(axis=1)
            k = np.minimum(k, n_activities - 1)
            logp[:, t] = log_prob[rows, k]
        correct = rng.random(n_sessions) < p[k, np.minimum(plays[rows, k], p.shape[1] - 1)]
        history[rows, k, plays[rows, k]] = correct
        plays[rows, k] += 1
        choices[:, t], outcomes[:, t] = k, correct
    return choices, outcomes, logp


def model_bounds(models: Sequence[str] = MODELS) -> dict[str, dict[str, tuple[float, float]]]:
    """Each model's fitted keys and their declared bounds (the experiment ten2021's ``fit`` of each condition).

    Parameters
    ----------
    models : sequence of str
        Conditions of the experiment ``ten2021`` (default :data:`MODELS`).

    Returns
    -------
    dict of str to dict of str to (float, float)
        Per model, its fitted keys and their bounds (:func:`~neurocur.fit.study.default_bounds`).
    """
    experiment = load_experiment("ten2021")
    return {name: default_bounds(experiment.conditions[name], list(experiment.conditions[name].fit), {})
            for name in models}


def coefficients(maps: pd.DataFrame, names: Sequence[str]) -> np.ndarray:
    """(subjects, len(FEATURES)) coefficient vectors of the subjects ``names`` from rows ``subject, param, estimate``
    (0 where absent; rows of other subjects are not read).

    Parameters
    ----------
    maps : pandas.DataFrame
        Rows ``subject, param, estimate`` of one model, ``param`` an experiment key (:data:`KEYS`).
    names : sequence of str
        The subjects, in the rows' order of the result.

    Returns
    -------
    numpy.ndarray
        (len(names), len(FEATURES)) coefficients, in :data:`FEATURES`' order.
    """
    coefs = np.zeros((len(names), len(FEATURES)))
    index = {name: i for i, name in enumerate(names)}
    for row in maps.itertuples():
        if str(row.subject) in index:
            coefs[index[str(row.subject)], FEATURES.index(KEYS[row.param])] = row.estimate
    return coefs


def fit_group(sessions: Sequence[Session], bounds: Mapping[str, Mapping[str, tuple[float, float]]], *, seed: int,
              starts: int = 3, n_samples: int = N_SAMPLES, max_iter: int = MAX_ITER, ml: bool = True) -> dict:
    """Every model of ``bounds`` fitted to the sessions: ``hierarchical`` (a row per model), ``evidence``
    (sessions x models, the Laplace log evidences under each group prior), ``maps`` (rows ``subject, model,
    param, estimate, ci_low, ci_high``) and, with ``ml``, ``ml`` (rows ``subject, model, loglik, n_params, n_obs,
    aic, bic`` and a column per fitted key, its estimate).

    Parameters
    ----------
    sessions : sequence of Session
        The participants.
    bounds : mapping of str to mapping of str to (float, float)
        Per model, its fitted keys (:data:`KEYS`) and their bounds (:func:`model_bounds`).
    seed : int
        The seed of every fit (:func:`~neurocur.fit.hierarchical.fit_hierarchical`, :func:`~neurocur.fit.mle.fit_ml`).
    starts : int
        Local searches of each subject's first E-step, and of each maximum-likelihood fit.
    n_samples : int
        Draws from the group prior for the sampled evidence and the iBIC.
    max_iter : int
        The most E-steps of each hierarchical fit.
    ml : bool
        Also fit every session alone by maximum likelihood.

    Returns
    -------
    dict
        ``hierarchical`` (pandas.DataFrame), ``evidence`` (numpy.ndarray), ``maps`` and ``ml`` (pandas.DataFrame,
        empty without ``ml``), as above.
    """
    names = [s.name for s in sessions]
    rows, maps, ml_rows, evidence = [], [], [], []
    for model, b in bounds.items():
        keys = list(b)
        fit = fit_hierarchical([s.subject(keys) for s in sessions], b, names=names, seed=seed, starts=starts,
                               n_samples=n_samples, max_iter=max_iter)
        summary = fit.summary()
        rows.append({"model": model, "ibic": fit.ibic, "ibic_laplace": fit.ibic_laplace,
                     **{k: summary[k] for k in ("log_evidence", "log_evidence_mcse", "log_evidence_laplace",
                                                "n_params", "n_obs", "iterations", "converged")}})
        evidence.append(fit.subject_log_evidence)
        maps.append(fit.subjects.rename(columns={"dataset": "subject"}).assign(model=model))
        if ml:
            for s in sessions:
                f = fit_ml(s.subject(keys), b, starts=starts, seed=seed, ci=None, dataset=s.name)
                ml_rows.append({"subject": s.name, "model": model, "loglik": f.loglik, "n_params": f.n_params,
                                "n_obs": f.n_obs, "aic": f.aic, "bic": f.bic, **f.estimate})
    maps = pd.concat(maps, ignore_index=True) if maps else pd.DataFrame()
    return {"hierarchical": pd.DataFrame(rows), "evidence": np.column_stack(evidence), "maps": maps,
            "ml": pd.DataFrame(ml_rows)}


