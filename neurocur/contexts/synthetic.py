"""The synthetic multi-context world of the paper's first experiment (section 4.1).

Each context shows one hidden driving force (a *source*, see :mod:`.sources`) through
a random linear mixing: a source of shape (n_steps, n_dims) is multiplied by a random
``(400, n_dims)`` matrix (one per source, drawn per run), each 400-vector is a 20×20
frame, and the values are scaled to [0, 1]. Five contexts by default: C1 and C2 share
S-A (the very same frames), C3, C4 and C5 show S-B, S-C and S-D.

Choices the paper leaves open (all options of :class:`SyntheticWorld`):

* ``normalise`` — ``"global"`` (default): one min–max scaling over all frames of a
  source (of each draw of a redrawn source; declared noise is centred and scaled
  symmetrically instead, :mod:`.user_sources`). The mixing stays affine, so the frames are exactly a linear process of the
  source ("hide each of these sources within a different high-dimensional process,
  albeit linearly, so that linear IncSFA will be able to extract them") and each
  context's Ω is its source's Ω (0.9933, 0.9988, 0.9997; 1 for S-D).
  ``"image"``: each frame min–max scaled on its own (the literal reading of
  "value-normalized from zero to one ... for each image"). This is a non-linear,
  scale-free map of the source: the frames span exactly three dimensions (the two
  mixing columns and a constant image), the order of Ω among S-A < S-B < S-C is
  kept but the values shift, and S-D's Ω drops below 1. A frame whose pixels are all
  equal (a zero source sample) becomes uniform 0.5.
* ``clock_offsets`` — each context has its own local clock (the context-state, in
  ``range(n_steps)``), which picks up where it left off and wraps at the end of the
  source. ``"random"`` (default): each clock starts at a uniform random step drawn per
  run, so C1 and C2, which share frames, are not replaying the same frames at the
  same states from the start. ``"zero"``: all clocks start at 0 (then C1 and C2 are
  indistinguishable until the agent's visits put them out of step). Or a list of
  one start step per context.
* ``nonstationary`` — ``True`` (default): a random source (S-D) is drawn afresh, with
  the same mixing matrix, each time the clock of a context showing it wraps, so S-D
  "changes irregularly" from one epoch to the next (Figure 4A) instead of replaying
  one fixed random walk. ``False``: one walk per run, replayed like the learnable
  sources. With a fixed walk the per-state cluster error of section 2.5 measures only
  how far the features move between visits, and a module whose features have stopped
  moving on S-D (they have no unique slowest direction to move to, Ω = 1) passes the
  freeze threshold: S-D would be "learned". The flag is also the default of declared
  noise sources; a declared source may set its own ``nonstationary`` (files and sinusoid
  pairs are then re-sampled every epoch: :mod:`.user_sources`).

Declared sources (``sources``, an experiment file's ``[world.sources]``: files, sinusoid
pairs, noise) and extrinsic rewards per context (``rewards``, :mod:`.rewards`) are
options too.

Per run (:meth:`SyntheticWorld.reset`), the world's generator draws, for each distinct
source in order of first appearance: the source itself if it is random (S-D), then
its mixing matrix (standard normal entries); then the clock offsets. A source that is
redrawn draws again from the same generator at each wrap of a clock showing it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from neurocur.config import ConfigError, ParamSpec, check_params, describe, param, spec_param
from neurocur.learn.correlation import abs_corr
from neurocur.learn.omega import omega

from .base import Episode, SourceSpec, World, register_world
from .mixing import NORMALISATIONS, SourceFrames, mix_frames
from .rewards import Rewards, check_rewards, rewards_param
from .sources import LEARNABLE, SLOW_DIM
from .user_sources import SOURCES_SPEC, check_sources, make_sources

__all__ = [
    "SyntheticParams",
    "SyntheticWorld",
    "PAPER_CONTEXTS",
    "SYNTHETIC",
    "NORMALISATIONS",
    "mix_frames",
]

PAPER_CONTEXTS = ("S-A", "S-A", "S-B", "S-C", "S-D")
"""The source of each of the paper's five contexts C1..C5."""

#: The synthetic world of section 4.1: C1, C2 share S-A; Ω(S-A) < Ω(S-B) < Ω(S-C); S-D is noise.
SYNTHETIC = SourceSpec(
    context_names=("C1", "C2", "C3", "C4", "C5"),
    context_sources=("S-A", "S-A", "S-B", "S-C", "S-D"),
    learnable=("S-A", "S-B", "S-C"),
)


_NAME = ParamSpec(str)
_NAMES = ParamSpec.sequence(_NAME, min_length=1)


@dataclass(frozen=True)
class SyntheticParams:
    """Parameters of :class:`SyntheticWorld` (an experiment file's ``[world]`` table, ``type = "synthetic"``).

    Checked as a whole on construction: the contexts' sources are built-in or given,
    given sources load and have equal lengths, names and offsets fit the contexts.

    Parameters
    ----------
    contexts : tuple of str
        The source of each context, built in (S-A, S-B, S-C, S-D) or a key of ``sources``.
    context_names : tuple of str, optional
        Distinct context names, one per context (default C1, C2, ...).
    sources : dict
        Declared sources by name: a ``.npy`` path, an array, or a ``SourceParams`` table (``.user_sources``).
    visit_length : int
        Frames per visit (100 in the paper).
    normalise : {"global", "image"}
        Min-max scaling per source (or draw) or per frame (module docstring).
    clock_offsets : {"random", "zero"} or tuple of int
        Where each context's local clock starts: drawn per run, 0, or one step per context.
    frame_shape : tuple of int
        ``(height, width)`` of a frame in pixels (20×20 in the paper).
    nonstationary : bool
        Redraw random sources (S-D, noise without a flag of its own) at every wrap of their clock.
    learnable : tuple of str, optional
        The learnable sources in Ω order, for the analysis (default: ``SyntheticWorld.source_spec``'s).
    rewards : tuple, optional
        Extrinsic reward per context, a number or a schedule each (``neurocur.contexts.rewards``).
    swap : tuple of str, optional
        A world event: the source of each context from ``swap_at`` on (one per context).
    swap_at : int
        Frames delivered before the swap takes effect, at the next visit that starts (with ``swap``).
    """

    contexts: tuple[str, ...] = spec_param(PAPER_CONTEXTS, _NAMES, doc="the source of each context")
    context_names: tuple[str, ...] | None = spec_param(
        None, ParamSpec.sequence(_NAME, min_length=1, optional=True), doc="distinct names; default C1, C2, ...")
    sources: dict = spec_param({}, SOURCES_SPEC, doc="declared driving forces: name -> a .npy file (relative to the "
                               "experiment file) or array, or a table (file, sinusoid or noise; .user_sources)")
    visit_length: int = param(100, int, low=1, doc="frames per visit")
    normalise: str = param("global", str, choices=NORMALISATIONS, doc="min-max scaling per source or per frame")
    clock_offsets: str | tuple[int, ...] = spec_param(
        "random", ParamSpec(tuple, item=ParamSpec(int, low=0), min_length=1, choices=("random", "zero")),
        doc="where each context's local clock starts")
    frame_shape: tuple[int, int] = spec_param((20, 20), ParamSpec.sequence(ParamSpec(int, low=1), length=2),
                                              doc="(height, width) in pixels")
    nonstationary: bool = param(True, bool, doc="redraw random sources (S-D, noise) at every wrap of their clock")
    learnable: tuple[str, ...] | None = spec_param(None, ParamSpec.sequence(_NAME, min_length=1, optional=True),
                                                   doc="learnable sources in Omega order, for the analysis")
    rewards: tuple | None = rewards_param()
    swap: tuple[str, ...] | None = spec_param(None, ParamSpec.sequence(_NAME, min_length=1, optional=True),
                                              doc="the source of each context from swap_at on (a world event)")
    swap_at: int = param(0, int, low=0, doc="frames delivered before the swap takes effect (with swap)")

    def __post_init__(self):
        check_params(self)
        where = type(self).__name__
        n = len(self.contexts)
        if self.swap is not None and len(self.swap) != n:
            raise ConfigError(where, "swap", f"{n} source names (one per context)", describe(self.swap))
        object.__setattr__(self, "_n_states", check_sources(self.sources, self.contexts + (self.swap or ()), where))
        if self.context_names is not None and (len(self.context_names) != n or len(set(self.context_names)) != n):
            raise ConfigError(where, "context_names", f"{n} distinct names (one per context)", describe(self.context_names))
        shown = self.contexts + (self.swap or ())
        if self.learnable is not None and any(s not in shown for s in self.learnable):
            raise ConfigError(where, "learnable", f"sources shown by a context ({', '.join(dict.fromkeys(shown))})",
                              describe(self.learnable))
        if isinstance(self.clock_offsets, tuple) and (
                len(self.clock_offsets) != n or max(self.clock_offsets) >= self.n_states):
            raise ConfigError(where, "clock_offsets", f"'random', 'zero' or {n} start steps in [0, {self.n_states})",
                              describe(self.clock_offsets))
        check_rewards(self, n, self.names)

    @property
    def names(self) -> tuple[str, ...]:
        """The context names: ``context_names``, or C1, C2, ..."""
        return self.context_names or tuple(f"C{i + 1}" for i in range(len(self.contexts)))

    @property
    def n_states(self) -> int:
        """Context-states: the length of the sources shown (1000 for the built-in ones)."""
        return self._n_states


@register_world("synthetic")
class SyntheticWorld(World):
    """Contexts that each show one driving force through a random linear mixing (section 4.1).

    Parameters
    ----------
    contexts : sequence of str
        The source of each context, by name (default: the paper's
        ``("S-A", "S-A", "S-B", "S-C", "S-D")``). The built-in names are S-A, S-B, S-C
        (sinusoid pairs) and S-D (an isotropic random walk drawn per run); any other
        name must be a key of ``sources``.
    sources : mapping, optional
        Declared driving forces ``{name: array (n_steps, n_dims)}``, rows are time,
        column :data:`~neurocur.contexts.sources.SLOW_DIM` the slow dimension (a name
        equal to a built-in replaces it), or ``{name: SourceParams or table}`` for files,
        sinusoid pairs, noise and re-sampled sources (:mod:`.user_sources`). All files
        and built-in sources shown must have the same ``n_steps``, which is the number of
        context-states; built-in sources have 1000.
    visit_length : int
        Frames per visit (100 in the paper).
    normalise : str
        ``"global"`` or ``"image"`` (see the module docstring).
    clock_offsets : str or sequence of int
        ``"random"``, ``"zero"`` or one start step per context.
    frame_shape : sequence of int
        The frame's (height, width); 20×20 in the paper.
    context_names : sequence of str, optional
        Defaults to ``C1``, ``C2``, ...
    nonstationary : bool
        Redraw random sources (S-D, and noise without a flag of its own) at every wrap of
        their clock (see the module docstring).
    learnable : sequence of str, optional
        The learnable sources in Ω order, for the analysis (:meth:`source_spec`); default:
        the built-in learnable sources shown, then the declared sources that are replayed
        (not noise, not re-sampled).
    rewards : sequence, optional
        Extrinsic reward per context, a number or a schedule each (:mod:`.rewards`).
    params : SyntheticParams, optional
        The world's parameters (an instance of its ``Params`` class, e.g. :class:`SyntheticParams`) instead
        of the keyword arguments (an experiment file's ``[world]`` table becomes one); the keyword
        arguments build one of that class and are checked by it too.

    Notes
    -----
    After :meth:`reset`, :meth:`source_of`, :meth:`source_signal` and
    :meth:`context_frames` expose the run's hidden sources for analysis.
    """

    Params = SyntheticParams
    #: Every draw's mixed frames are checked finite when rendered (:func:`.mixing.frame_limits`),
    #: and min-max scaling then maps them into [0, 1] exactly.
    frames_conform = True

    def __init__(
        self,
        contexts: Sequence[str] = PAPER_CONTEXTS,
        *,
        sources: Mapping[str, np.ndarray | Mapping] | None = None,
        visit_length: int = 100,
        normalise: str = "global",
        clock_offsets: str | Sequence[int] = "random",
        frame_shape: Sequence[int] = (20, 20),
        context_names: Sequence[str] | None = None,
        nonstationary: bool = True,
        learnable: Sequence[str] | None = None,
        rewards: Sequence | None = None,
        params: SyntheticParams | None = None,
    ) -> None:
        super().__init__()
        if params is None:
            params = self.Params(contexts=contexts, sources=dict(sources or {}), visit_length=visit_length,
                                     normalise=normalise, clock_offsets=clock_offsets, frame_shape=frame_shape,
                                     context_names=context_names, nonstationary=nonstationary, learnable=learnable,
                                     rewards=rewards)
        p = self.params = params
        self._sources = make_sources(p.contexts + (p.swap or ()), p.sources, p.n_states, p.nonstationary)
        self.rewards = Rewards.of(p.rewards)
        self.source_names = p.contexts
        self.context_names = p.names
        self.n_states = p.n_states
        self.frame_shape = p.frame_shape
        self.visit_length = self.max_frames = p.visit_length
        self.normalise = p.normalise
        self.clock_offsets = p.clock_offsets
        self.nonstationary = p.nonstationary
        self.learnable = p.learnable
        self._shown: dict[str, SourceFrames] = {}
        self._clocks = np.zeros(self.n_contexts, dtype=np.int64)

    @classmethod
    def from_sources(cls, sources: Mapping[str, np.ndarray], contexts: Sequence[str] | None = None, **kwargs):
        """A world of user driving forces ``{name: (n_steps, n_dims) array}``.

        ``contexts`` lists the source of each context (default: one context per
        source, in the given order); other keyword arguments as for the constructor.
        """
        if not sources:
            raise ValueError("from_sources needs at least one source")
        return cls(list(sources) if contexts is None else contexts, sources=sources, **kwargs)

    # -- World API ---------------------------------------------------------------------------

    def _reset(self) -> None:
        rng = self.np_random
        self._shown.clear()
        for name, source in self._sources.items():
            signal = source.draw(rng, self.n_states)
            mixing = rng.standard_normal((self.n_pixels, signal.shape[1]))
            shown = self._shown[name] = SourceFrames(mixing, self.normalise, symmetric=source.centred,
                                                     whole=not source.redraws)
            shown.show(signal)
        self.source_names, self.frames_delivered = self.params.contexts, 0
        if self.clock_offsets == "random":
            self._clocks = rng.integers(0, self.n_states, size=self.n_contexts).astype(np.int64)
        elif self.clock_offsets == "zero":
            self._clocks = np.zeros(self.n_contexts, dtype=np.int64)
        else:
            self._clocks = np.array(self.clock_offsets, dtype=np.int64)

    def _visit(self, context: int) -> Episode:
        return self._visits(context, 1)

    def _visits(self, context: int, n: int) -> Episode:
        """The next ``n`` visits of ``context`` (the next ``n * visit_length`` steps of its clock),
        unpaid. Read-only frames: a view of the rendered frames when the clock does not wrap.
        The swap (a world event) takes effect at the first visit that starts once ``swap_at``
        frames have been delivered: from then on context c shows ``swap[c]``, its clock going on."""
        if self.params.swap is not None and self.frames_delivered >= self.params.swap_at:
            self.source_names = self.params.swap
        self.frames_delivered += n * self.visit_length
        shown, source = self._require(self.source_names[context]), self._sources[self.source_names[context]]
        T, N = n * self.visit_length, self.n_states
        start = int(self._clocks[context])
        states = np.arange(start, start + T, dtype=np.int64)
        if start + T > N:
            states %= N
        if not source.redraws:
            frames = shown.frames()[start : start + T] if start + T <= N else shown.frames()[states]
        else:
            frames, a = np.empty((T, len(shown.mixing))), 0
            for b in range(N - start, T + 1, N):  # the clock wraps after row b - 1 (at the end too): a new draw
                shown.scale_rows(int(states[a]), frames[a:b])
                shown.show(source.draw(self.np_random, N))
                a = b
            if a < T:
                shown.scale_rows(int(states[a]), frames[a:])
        frames.flags.writeable = False
        self._clocks[context] = (start + T) % N
        return Episode(frames=frames, states=states, context=context,
                       starts=np.arange(0, T, self.visit_length, dtype=np.int64))

    def source_spec(self) -> SourceSpec:
        """Learnable sources: ``learnable`` if given, else the built-in learnable sources shown
        (S-A, S-B, S-C, in Ω order) followed by the other replayed sources (files, sinusoid
        pairs) in context order."""
        learnable = [name for name, source in self._sources.items() if source.learnable and name in self.source_names]
        default = [s for s in LEARNABLE if s in learnable] + [s for s in learnable if s not in LEARNABLE]
        learnable = default if self.learnable is None else self.learnable
        return SourceSpec(tuple(self.context_names), tuple(self.source_names), tuple(learnable))

    def module_report(self, library, modules):
        """Per stored module: its source and the |corr| of its slowest output, on its context's
        frames, with the source's slow dimension (:data:`~neurocur.contexts.sources.SLOW_DIM`)."""
        sources, quality = [], []
        for row in modules.itertuples(index=False):
            source = self.source_at(int(row.context), int(row.step))
            sources.append(source)
            output = library[int(row.module)].transform(self.context_frames(int(row.context)))[:, 0]
            quality.append(abs_corr(output, self.source_signal(source)[:, SLOW_DIM]))
        return sources, quality, {}, {}

    # -- hidden sources, for analysis ----------------------------------------------------------

    def source_of(self, context) -> str:
        """Name of the source shown by ``context`` (index or context name)."""
        return self.source_names[self._index(context)]

    def source_at(self, context: int, step: int) -> str:
        """The source ``context`` showed at global frame ``step`` (before or after the swap)."""
        p = self.params
        return (p.swap if p.swap is not None and step >= p.swap_at else p.contexts)[context]

    def source_signal(self, name: str) -> np.ndarray:
        """This run's driving force ``name``, shape (n_steps, n_dims), read-only."""
        return self._require(name).signal

    def mixing(self, name: str) -> np.ndarray:
        """This run's mixing matrix of source ``name``, shape (n_pixels, n_dims), read-only."""
        return self._require(name).mixing

    def normalisation_limits(self, name: str) -> tuple[float, float]:
        """The raw (low, high) mapped to [0, 1] under ``normalise="global"``."""
        return self._require(name).limits

    def context_frames(self, context) -> np.ndarray:
        """All frames of ``context`` in local-time order, (n_steps, n_pixels), read-only (of a
        redrawn source: its current draw)."""
        return self._require(self.source_of(context)).frames()

    def redraws(self, context) -> bool:
        """Whether the source of ``context`` is drawn again every epoch (S-D, noise, re-sampled files)."""
        return self._sources[self.source_of(context)].redraws

    def omega(self, context, eta: float = 0.05, *, draws: int = 10, seed=0) -> tuple[float, np.ndarray]:
        """Ω (eq 40, MCA rate ``eta``) of the frames of ``context``: ``(value, per_draw)``.

        A replayed source: Ω of this run's frames, and ``per_draw`` holds that one value. A
        source redrawn every epoch (:meth:`redraws`) has no single sequence of frames: Ω is
        measured on ``draws`` fresh draws, rendered with this run's mixing from a generator
        seeded by ``seed`` (the world's own stream is left alone). ``per_draw`` holds each
        draw's Ω (what a learner would face if that draw were replayed), and ``value`` is Ω
        of the draws joined, with no derivative across a redraw: the learning cost of the
        process the learner sees over ``draws`` epochs. For noise, per-draw Ω lies below 1
        by sampling error alone (white noise: about 0.994) and the joined value tends to the
        process's Ω = 1 as ``draws`` grows.
        """
        name = self.source_of(context)
        # frames lie in the span of the mixing columns and the constant image; Ω is the same in
        # the coordinates of an orthonormal basis of that span, which are far cheaper to whiten
        basis = np.linalg.qr(np.column_stack([self.mixing(name), np.ones(self.n_pixels)]))[0]
        if not self.redraws(context):
            value = omega(self.context_frames(context) @ basis, eta)
            return value, np.array([value])
        rng, source = np.random.default_rng(seed), self._sources[name]
        frames = [self._shown[name].render(source.draw(rng, self.n_states))[0] @ basis for _ in range(draws)]
        per_draw = np.array([omega(f, eta) for f in frames])
        return omega(np.concatenate(frames), eta, starts=np.arange(draws) * self.n_states), per_draw

    def clock(self, context) -> int:
        """The local time step at which the next visit of ``context`` starts."""
        return int(self._clocks[self._index(context)])

    def _index(self, context) -> int:
        if isinstance(context, str):
            if context not in self.context_names:
                raise ValueError(f"unknown context {context!r}; expected one of {', '.join(self.context_names)}")
            return self.context_names.index(context)
        return self._check_context(context)

    def _require(self, name) -> SourceFrames:
        if not self._shown:
            raise RuntimeError("the world has not been reset yet: call world.reset(seed=...) first")
        if name not in self._shown:
            raise ValueError(f"unknown source {name!r}; this world shows {', '.join(dict.fromkeys(self.source_names))}")
        return self._shown[name]
