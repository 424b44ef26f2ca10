"""EC: the entorhinal slow-feature layer — the adaptive IncSFA module and the library (eqs 1-2)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import ConfigError, check_params, learner_param, param
from ..learn.ccipca import AmnesicSchedule
from ..learn.incsfa import IncSFA
from .base import Probe, Region, Signal, register


@dataclass(frozen=True)
class ECParams:
    """Every parameter is IncSFA's, with IncSFA's spec (type and range)."""

    n_components: int = learner_param(IncSFA, "n_components", 2, doc="J, slow features per module")
    n_pca: int = learner_param(IncSFA, "n_pca", 3, doc="K, whitened dimensions kept by CCIPCA")
    amnesic: float | AmnesicSchedule = learner_param(IncSFA, "amnesic", 2.0,
                                                     doc="CCIPCA amnesic parameter l (or an AmnesicSchedule)")
    var_fraction: float | None = learner_param(IncSFA, "var_fraction", None,
                                               doc="keep the fewest components explaining this variance fraction")
    eig_cutoff: float = learner_param(IncSFA, "eig_cutoff", 1e-3,
                                      doc="relative eigenvalue below which a component is dropped")
    orthonormalize: int = learner_param(IncSFA, "orthonormalize", 100,
                                        doc="re-orthonormalise the CCIPCA directions every this many samples (0: never, Algorithm 2)")
    mca_rate: float = learner_param(IncSFA, "mca_rate", 0.05, doc="MCA learning rate")
    mca_rates: str = learner_param(IncSFA, "mca_rates", "equal",
                                   doc="'equal' (the paper) or 'decreasing' (slower rates for the faster features)")
    gamma: float | str = learner_param(IncSFA, "gamma", 4.0, doc="MCA deflation gamma")
    dtype: str = learner_param(IncSFA, "dtype", "float64",
                               doc="'float64' (exact) or 'float32' (faster, not bit-identical)")
    ne_gain: float = param(0.0, float, low=0.0,
                           doc="k: MCA rate x (1 + k NE), NE the learn input 'ne' (0: off, and no such input)")

    def __post_init__(self):
        check_params(self)
        if self.n_components > self.n_pca:
            raise ConfigError(type(self).__name__, "n_components", f"at most n_pca = {self.n_pca}", repr(self.n_components))


@register("ec.incsfa")
class ECIncSFA(Region):
    """Slow-feature encoding by every module of the library plus the adaptive one.

    Step: ``y^i = (x - mean_i) W^i`` (eq 2; ``W^i`` = whitening x MCA = ``projection_``)
    for every frame of the episode, one matrix product for all frozen modules (their
    projections stacked) and one for the adaptive module (its projection is cached
    after each update; a fresh module outputs zeros until its first update).
    Learn (runs after HPC has stepped):

    - on HPC's module-learned event: the adaptive module, exactly as it encoded this
      episode, is copied into the library (long-term memory, section 2.6) and a fresh
      adaptive module starts with a seed drawn from this region's generator;
    - else, unless the episode is familiar (gating, section 2.6):
      ``IncSFA.partial_fit`` on each independent segment of the episode.

    ``slowness_progress`` (an optional output, computed only when an edge reads it, as
    ``circuits/vta_slowness_progress.toml``'s does; a variant, not the paper's reward): how much
    slower the adaptive module's slowest output has become on this context since the context's
    previous visit, measured on this episode's frames. With eq 4's Δ = <ẏ²> (within segments;
    IncSFA keeps the output at unit variance), it is Δ(y₀ under the projection of the context's
    previous visit) − Δ(y₀ now). Section 4.4's Ω quantifies learning progress as the convergence
    of this output (CIMCA, eqs 16-17), so the drop of its Δ is that progress on the module's own
    objective. NaN while undefined (a fresh module, or the context's first visit with this module).
    """

    Params = ECParams
    inputs = (Signal("episode", "Episode", ()),)
    GATING = (
        Signal("familiar", "bool", (), "some frozen module's error is below threshold: do not learn"),
        Signal("module_learned", "bool", (), "freeze the adaptive module now"),
    )
    NE = Signal("ne", "float64", (), "noradrenaline that scales the MCA rate (only with ne_gain > 0)")
    outputs = (
        Signal("features", "float64", ("T", "J"), "adaptive module's slow features per frame"),
        Signal("library_features", "float64", ("T", "M", "J"), "every frozen module's slow features per frame"),
        Signal("slowness_progress", "float64", (), "drop of the slowest output's delta on this episode's frames "
               "since the context's previous visit (NaN while undefined or unread)", optional=True),
    )

    @property
    def learn_inputs(self):
        """HPC's gating signals, and ``ne`` when ``ne_gain`` > 0 (the NE-gated variant)."""
        return (*self.GATING, self.NE) if self.params.ne_gain > 0 else self.GATING

    @property
    def frame_probes(self):
        return tuple(Probe(f"y{j}", "float", "a.u. (unit variance)", f"adaptive slow feature {j}")
                     for j in range(self.params.n_components))

    def reset(self, rng) -> None:
        self.rng = rng
        self.library: list[IncSFA] = []
        self._lib_proj = None
        self._lib_offset = None
        self.adaptive = self._new_module()
        self.features = None

    def _new_module(self) -> IncSFA:
        p = self.params
        self._proj = self._offset = None
        self._seen: dict[int, np.ndarray] = {}  # context -> the slowest output's projection at its last visit
        return IncSFA(p.n_components, p.n_pca, amnesic=p.amnesic, var_fraction=p.var_fraction,
                      eig_cutoff=p.eig_cutoff, orthonormalize=p.orthonormalize, mca_rate=p.mca_rate,
                      mca_rates=p.mca_rates, gamma=p.gamma, random_state=int(self.rng.integers(2**63)), dtype=p.dtype)

    def step(self, episode):
        X = episode.frames
        T, J = len(X), self.params.n_components
        if self._proj is None:  # a fresh module encodes nothing yet
            y = np.zeros((T, J))
        else:
            y = X @ self._proj - self._offset
        if self.library:
            lib = (X @ self._lib_proj - self._lib_offset).reshape(T, len(self.library), J)
        else:
            lib = np.empty((T, 0, J))
        self.episode, self.features = episode, y
        return y, lib, self._slowness_progress(episode, y)

    def _slowness_progress(self, episode, y) -> float:
        """Δ(y₀) under the context's previous projection minus Δ(y₀) now, on this episode's frames."""
        if "slowness_progress" not in self.wired or self._proj is None:
            return np.nan
        before = self._seen.get(episode.context)
        self._seen[episode.context] = self._proj[:, 0].copy()
        if before is None:
            return np.nan
        return _delta(episode.frames @ before, episode) - _delta(y[:, 0], episode)  # offsets cancel in Δ

    def learn(self, familiar, module_learned, ne=None) -> None:
        if module_learned:
            self.library.append(self.adaptive.copy())
            self._lib_proj = np.concatenate([m.projection_ for m in self.library], axis=1)
            self._lib_offset = np.concatenate([m.mean_ @ m.projection_ for m in self.library])
            self.adaptive = self._new_module()
        elif not familiar:
            a = self.adaptive
            if self.params.ne_gain > 0:
                a.set_params(mca_rate=ne_rate(self.params, ne))
            for frames, _ in self.episode.segments():  # the frame contract has checked them (float64, [0, 1])
                a.partial_fit(frames, check_input=False)
            self._proj = a.projection_
            self._offset = a.mean_ @ self._proj

    def record_frames(self):
        return self.features

    def products(self, events):
        """``"library"``: the frozen modules (IncSFA), in storage order."""
        return {"library": list(self.library)}


def ne_rate(p: ECParams, ne) -> float:
    """The NE-gated MCA rate, eta (1 + k NE) capped at 0.5 (eq 20's convergence bound); NE = 0 on
    the first pass (a delayed edge delivers None) and below 0 counts as 0. A learning-rate gain
    in the spirit of Yu & Dayan (2005, Neuron 46:681): NE reports unexpected uncertainty and
    speeds learning; not in the paper."""
    level = 0.0 if ne is None else max(0.0, float(ne))
    return min(0.5, p.mca_rate * (1.0 + p.ne_gain * level))


def _delta(y: np.ndarray, episode) -> float:
    """Eq 4's Δ = <ẏ²> of one output over the episode's block: the mean squared difference of
    successive frames, none spanning an independent episode's start."""
    dy = episode.derivative(y)
    return float(np.mean(dy[~np.isnan(dy)] ** 2))
