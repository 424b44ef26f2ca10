"""HPC: the hippocampal competitive layer — ROC clusterers, estimation errors, familiarity and storage."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..config import check_params, learner_param, param, spec_param
from ..contract import MODULE_COLUMNS
from ..learn.roc import MIN_WEIGHT, ROCBank
from ._hpc_kernels import store_errors
from .base import Probe, Region, Signal, register

FREEZE_RULES = ("context_mean", "context_sum", "episode_mean", "converged")


@dataclass(frozen=True)
class HPCParams:
    threshold: float = param(0.3, float, low=0.0, low_open=True, doc="familiarity and freeze threshold")
    n_states: int = param(1000, int, low=1, doc="context-states per context (>= the world's)")
    max_clusters: int = learner_param(ROCBank, "max_clusters", 2,
                                      doc="xi, clusters per context-state (Algorithm 3 merges pairs)")
    amnesic: float = learner_param(ROCBank, "amnesic", 0.01, doc="phi, ROC weight leak per update")
    width: float = learner_param(ROCBank, "width", 1.0, doc="sigma of the Gaussian ROC response")
    prune_min_weight: float = spec_param(0.5, MIN_WEIGHT, doc="clusters lighter than this are pruned at storage")
    freeze: str = param("context_mean", str, choices=FREEZE_RULES, doc="module storage rule")
    ordered: bool = param(False, bool,
                          doc="variant: store a module only if its outputs on the context are ordered by slowness (eq 4)")
    drift_ratios: int = param(1, int, low=1,
                              doc="converged: successive visit-to-visit error ratios that must all shrink (rho: the largest)")
    reward_error: str = param("context", str, choices=("context", "episode"), doc="error sent to VTA")
    clusterers: str = param("context_state", str, choices=("context_state", "state"),
                            doc="one clusterer per (context, state) or per state shared by all contexts")
    gating: bool = param(True, bool, doc="familiar episodes gate learning (False: never familiar)")
    min_spread: float = param(0.0, float, low=0.0,
                              doc="a module whose output spread on an episode is below this neither gates nor is stored")
    error_scale: str = param("absolute", str, choices=("absolute", "spread"),
                             doc="eq 10 as a feature distance, or divided by the episode's feature spread")

    def __post_init__(self):
        check_params(self)


@register("hpc.roc")
class HPCROC(Region):
    """ROC clusterers on the slow features (eq 3, Algorithm 3) and the estimation errors.

    Step, for the episode's frames with context-states ``s`` and context ``c``:

    - every frozen module m: eq 10 error ``min_j ||y^m(t) - c^m_j(s_t)||`` per frame,
      averaged over the frames whose state has a cluster; ``min_frozen_error`` is the
      smallest average, ``gating_module`` its module; ``familiar`` =
      ``gating and min_frozen_error < threshold`` (section 2.6);
    - the adaptive module: eq 10 error per frame against the current clusters
      (``episode_error`` = their mean); the stored error ``e^i`` of each visited
      (context, state) is overwritten with it (eq 10: "updated whenever the agent
      visits that state"); the context error ``error`` is the mean of the context's
      stored errors (eq 11 divided by M; NaN until a state has one);
    - ``module_learned`` = freeze rule and not familiar. Rules: ``context_mean``
      (every state of the context has a stored error and their mean < threshold),
      ``context_sum`` (same, eq 11's literal sum < threshold), ``episode_mean``
      (``episode_error`` < threshold, the literal reading of section 4.1.2), and the
      variant ``converged`` (not in the paper; see below). A state whose last visit was
      familiar needs no stored error in ``context_mean`` and ``converged``: the gating
      module explains it (section 2.6), and the adaptive module, which learns nothing on
      a familiar episode, never has a cluster there, so a partly gated context could
      otherwise never be stored;
    - ``reward_error`` (to VTA): the context error (``"context"``) or ``episode_error``;
    - ``progress`` (an optional output, :class:`~neurocur.regions.vta_state_progress.StateProgressVTA`'s
      input): the mean, over the frames whose state has a stored error from its previous
      visit and an error now, of the stored error minus the error now. It is eq 11's
      decrease over the visit per frame: each state is compared with itself, the other
      states of the context do not dilute it (the context error's 1/M) and a block of two
      visits does not double it. NaN when no frame has both.

    The ``converged`` rule asks that the features have converged, not merely stopped
    moving. With the sources replayed identically each epoch, a state's error measures
    how far the features moved since the state's previous visit; under MCA (eqs 16-23)
    that drift shrinks geometrically by a factor rho per visit (rho ~ Omega^samples, so
    slow-to-learn sources drift little per visit long before they have converged). The
    rule estimates ``rho`` as the ratio of the context's summed stored errors to the
    summed errors those states had at their previous visit, and extrapolates the drift
    still to come, ``E / (1 - rho)`` (a geometric tail, as in Aitken's extrapolation).
    It fires when every state has two stored errors and this extrapolated drift is
    below the threshold; a source whose error does not shrink (rho >= 1) never fires.
    With ``drift_ratios = n > 1`` every state needs n + 1 stored errors, each of the n
    successive ratios of summed errors (this visit to the previous, the previous to the
    one before, ...) must be below 1, and rho is the largest of them. The drift is not
    always geometric: a slow feature that starts near a faster direction leaves it
    slowly, so its drift per visit first *grows*, and a single ratio taken just after the
    whitening settles (errors falling ten-fold in one visit) predicts almost no drift to
    come (docs/reproduction.md, "Learning times").

    ``ordered`` (a variant, not in the paper; off by default) stores the adaptive module
    only if its outputs on the context are ordered by slowness, as SFA's solution is
    (eqs 4-7): Δ_j = <ẏ_j²> / var(y_j) does not decrease with j, taken like the context
    error over the latest visit of every state of the context (each state keeps its last
    outputs and their derivatives; none across a start). A slowest output still sitting on
    a faster direction (a saddle of CIMCA, which it leaves only slowly) hardly moves
    between visits, so the drift-based rules would store it; its outputs are then out of
    order. One episode is too short a sample: two outputs of nearly equal slowness (a
    module whose whitening was fitted to other contexts) pass on some episodes by chance.

    ``error_scale = "spread"`` (a variant, not in the paper) divides every frame's eq-10
    error by the module's output spread on the episode, sqrt(mean_t ||y_t - mean(y)||^2).
    Eq 10 is a distance in feature units, so a module whose features barely respond to
    a context's input (its whitening was fitted to other sources) has a tiny error
    there and would count as having learned, or as gating, that context; divided by
    the spread, such a module's error is of order one.

    ``min_spread`` (a variant, not in the paper; 0 turns it off) keeps the errors in
    feature units but asks a module to respond before its small error counts: a frozen
    module gates an episode only if its output spread there is at least ``min_spread``,
    and the adaptive module is stored only on an episode where its spread is.

    Learn: unless familiar, ``ROCBank.partial_fit`` on the adaptive features of this
    pass (computed before EC's update). On module-learned the bank is then pruned
    (``prune_min_weight``; never a state's latest-sample cluster), stored with the
    frozen EC module, and a fresh bank and stored-error table start.
    With ``clusterers = "context_state"`` clusterer ``c * n_states + s`` serves state s
    of context c; with ``"state"`` all contexts share clusterer s (the paper's "1000
    clusterers"), so a frozen module also gates other contexts showing its source.
    """

    Params = HPCParams
    inputs = (
        Signal("episode", "Episode", ()),
        Signal("features", "float64", ("T", "J")),
        Signal("library_features", "float64", ("T", "M", "J")),
    )
    outputs = (
        Signal("familiar", "bool", (), "a frozen module's error is below threshold"),
        Signal("module_learned", "bool", (), "the adaptive module is stored at this pass"),
        Signal("reward_error", "float64", (), "adaptive module's error used for the intrinsic reward"),
        Signal("progress", "float64", (), "drop of the adaptive module's error at this episode's states since their "
               "previous visit, per frame (NaN while undefined)", optional=True),
    )
    probes = (
        Probe("familiar", "bool", "", "gated: a frozen module's mean error < threshold"),
        Probe("gating_module", "int", "index", "frozen module that gates this episode; -1 if none"),
        Probe("error", "float", "feature distance", "adaptive context error: mean of stored eq-10 errors (eq 11 / M)"),
        Probe("episode_error", "float", "feature distance", "mean eq-10 error of this episode's frames"),
        Probe("min_frozen_error", "float", "feature distance", "smallest frozen module's mean eq-10 error; NaN if none"),
        Probe("module_learned", "bool", "", "the freeze rule fired on an unfamiliar episode"),
        Probe("n_modules", "int", "modules", "library size after this episode"),
    )
    frame_probes = (Probe("frame_error", "float", "feature distance", "adaptive eq-10 error per frame (NaN: no cluster)"),)
    lesions = {"no_gating": {"gating": False}}

    @property
    def threshold(self) -> float:
        """The familiarity and freeze threshold."""
        return self.params.threshold

    def bind(self, world) -> None:
        p = self.params
        if world.n_states > p.n_states:
            raise ValueError(f"{self.name}: n_states = {p.n_states} is smaller than the world's {world.n_states} context-states")
        self.n_contexts, self.m = world.n_contexts, world.n_states
        self.n_clusterers = p.n_states * (self.n_contexts if p.clusterers == "context_state" else 1)

    def reset(self, rng) -> None:
        self.library: list[ROCBank] = []
        self.gated = np.zeros((self.n_contexts, self.m), dtype=bool)  # each state's last visit was familiar
        self._new_bank()

    def _new_bank(self) -> None:
        self.bank = None  # created at the first step, when the feature dimension is known
        # each state's error at its last visit (``stored``, row 0), at the visit before (row 1), ...
        self.history = np.full((self.params.drift_ratios + 1, self.n_contexts, self.m), np.nan)
        self.stored = self.history[0]
        self.state_outputs = self.state_derivatives = None  # (contexts, states, J): each state's last, for ``ordered``

    def step(self, episode, features, library_features):
        p = self.params
        c = episode.context
        idx = episode.states + c * p.n_states if p.clusterers == "context_state" else episode.states
        min_err, gating = np.nan, -1
        for m, bank in enumerate(self.library):
            _, _, e, responds = self._errors(bank, idx, library_features[:, m, :])
            e = e if responds else np.nan
            if e < min_err or (e == e and min_err != min_err):
                min_err, gating = e, m
        familiar = bool(p.gating and min_err < p.threshold and self.retrieval_allowed())
        if not familiar:
            gating = -1
        self.gated[c, episode.states] = familiar
        if self.bank is None:
            self.bank = ROCBank(self.n_clusterers, features.shape[1], max_clusters=p.max_clusters,
                                amnesic=p.amnesic, width=p.width)
        err, known, ep_err, responds = self._errors(self.bank, idx, features)
        # a state seen only in gated episodes has no error (nothing is learned there): a frozen module explains it
        ctx_err, total, complete, drift, progress = store_errors(self.history[:, c], self.gated[c], episode.states, err, known)
        if p.freeze == "context_mean":
            rule = ctx_err < p.threshold and complete
        elif p.freeze == "context_sum":
            rule = total < p.threshold
        elif p.freeze == "episode_mean":
            rule = ep_err < p.threshold
        else:
            rule = complete and drift < p.threshold
        learned = bool(rule and not familiar and responds)
        if p.ordered:
            self._keep_outputs(episode, features)
            learned = learned and self.ordered(c)  # read only when it decides: it scans every state
        self._frame_err, self._known = err, known
        self._idx, self._features, self._context = idx, features, c
        self.familiar, self.module_learned = familiar, learned
        self._rec = (familiar, gating, ctx_err, ep_err, min_err, learned)
        reward_error = float(ctx_err if p.reward_error == "context" else ep_err)
        return familiar, learned, reward_error, progress

    def retrieval_allowed(self) -> bool:
        """Whether a frozen module below threshold may gate this episode (always here; a variant
        whose retrieval is gated by another signal, :class:`~neurocur.regions.hpc_ach.HPCACh`, overrides it)."""
        return True

    def _keep_outputs(self, episode, y: np.ndarray) -> None:
        """Keep each visited state's outputs and derivatives (no derivative across a start)."""
        if self.state_outputs is None:
            self.state_outputs = np.full((self.n_contexts, self.m, y.shape[1]), np.nan)
            self.state_derivatives = np.full_like(self.state_outputs, np.nan)
        c, states = episode.context, episode.states
        self.state_outputs[c, states] = y
        self.state_derivatives[c, states] = episode.derivative(y)

    def ordered(self, context: int) -> bool:
        """Whether the adaptive module's outputs on ``context``, over the latest visit of each
        state, are ordered by slowness (``ordered``; needs that option on)."""
        if self.state_outputs is None:
            return False
        return _slowness_ordered(self.state_outputs[context], self.state_derivatives[context])

    def _errors(self, bank: ROCBank, idx: np.ndarray, y: np.ndarray):
        """Eq-10 errors of a module's outputs ``y`` per frame, the ``known`` mask, their mean over the
        known frames, and whether the module responds.

        Errors are divided by the episode's feature spread under ``error_scale =
        "spread"``; the module responds when that spread is at least ``min_spread``.
        The spread is computed only when one of the two options needs it.
        """
        p = self.params
        divide = p.error_scale == "spread"
        need = divide or p.min_spread != 0.0
        err, known, mean, spread = bank.episode_error(idx, y, spread=need, divide=divide)
        return err, known, mean, (spread >= p.min_spread if need else True)

    def learn(self) -> None:
        if self.familiar:
            return
        self.bank.partial_fit(self._idx, self._features)
        if self.module_learned:
            self.bank.prune(self.params.prune_min_weight)
            self.library.append(self.bank)
            self.events.append({"event": "module_stored", "module": len(self.library) - 1,
                                "context": int(self._context), "n_clusters": int(self.bank.n_clusters_.sum())})
            self._new_bank()

    def record(self):
        return self._rec + (len(self.library),)

    def record_frames(self):
        return np.where(self._known, self._frame_err, np.nan)[:, None]

    def products(self, events):
        """``"modules"``: one row per stored module (:data:`neurocur.contract.MODULE_COLUMNS`)."""
        columns = [c.name for c in MODULE_COLUMNS]
        stored = events[events["event"] == "module_stored"]
        if stored.empty:
            return {"modules": pd.DataFrame({c: np.empty(0, np.int64) for c in columns})}
        return {"modules": stored[columns].astype(np.int64).reset_index(drop=True)}


def _slowness_ordered(y: np.ndarray, dy: np.ndarray) -> bool:
    """Whether Δ_j = mean(dy_j²) / var(y_j) (eq 4 for unit-variance outputs) does not
    decrease with j; NaN rows are left out. False if an output is constant or no
    derivative is known."""
    keep = ~np.isnan(dy[:, 0])
    var = np.nanvar(y, axis=0)
    if not keep.any() or not (var > 0).all():
        return False
    delta = (dy[keep] ** 2).mean(axis=0) / var
    return bool((np.diff(delta) >= 0).all())


def extrapolated_drift(history: np.ndarray) -> float:
    """The ``converged`` rule's extrapolated remaining drift of one context's stored errors
    ``history`` ((n + 1, states), newest first, as ``HPCROC.history[:, c]``); reads, stores nothing."""
    history = np.array(history, dtype=np.float64)
    none = np.empty(0, dtype=np.int64)
    return store_errors(history, np.zeros(history.shape[1], dtype=bool), none, np.empty(0), none.astype(bool))[3]
