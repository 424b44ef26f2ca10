"""The Region base class, signal specs and probe specs.

A region is one brain area. It declares

- ``Params``: a frozen dataclass of parameters (fields made with
  :func:`neurocur.config.param`, validated on construction);
- ``inputs``: signals read in the step phase, ``learn_inputs``: signals read only in
  the learn phase, ``outputs``: signals it produces in the step phase (all
  :class:`Signal`, in the order of the arguments of ``step``/``learn`` and of the
  tuple ``step`` returns);
- ``probes``: per-episode recordable quantities (:class:`Probe`, returned in order by
  ``record()``) and ``frame_probes``: per-frame quantities (``record_frames()``
  returns a (T, n) array), recorded only on request;
- ``lesions``: named lesions, each a dict of parameter overrides.

Life cycle, driven by the scheduler: ``wired`` is set to the names of the outputs some edge reads
(an optional output none reads may be left uncomputed), then ``bind(world)`` once (sizes from the world),
``reset(rng)`` once, then per pass (= one episode) ``step(*inputs) -> tuple`` in
topological order, then ``learn(*learn_inputs)`` for plastic regions, then
``record()``. A region may append event dicts to ``self.events`` (the scheduler
collects and clears them after each pass). At the end of a run, ``products(events)``
returns what the region leaves behind, by name (EC: ``"library"``, its frozen modules;
HPC: ``"modules"``, the stored-module table); :meth:`neurocur.scheduler.Simulator.products`
gathers them, so nothing above the regions names a region to find them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd

from ..config import check_params
from ..registry import Registry

__all__ = ["REGIONS", "Signal", "Probe", "Region", "NoParams", "register"]

#: Region types by name; third-party region types come from the entry-point group ``neurocur.regions``.
REGIONS = Registry("region", "neurocur.regions")
#: Class decorator: ``@register("vta.learning_progress")``.
register = REGIONS.register


@dataclass(frozen=True)
class Signal:
    """A named port. ``dtype`` is a string (``"float64"``, ``"int64"``, ``"bool"``,
    ``"Episode"``); ``shape`` a tuple of ints (fixed sizes) or strings (named sizes
    that vary, e.g. ``"T"`` frames); ``()`` is a scalar. ``initial`` is the value a
    delayed edge delivers on the first pass. An ``optional`` output may go nowhere (a
    signal other regions can read when a circuit wires it, e.g. LC's NE); every other
    output needs an edge.

    Parameters
    ----------
    name : str
        The port's name, unique among the region's inputs (or outputs).
    dtype : str
        ``"float64"``, ``"int64"``, ``"bool"`` or ``"Episode"``.
    shape : tuple of int or str
        Fixed sizes, or named sizes that vary (``"T"``); ``()`` for a scalar.
    doc : str
        What the signal is, for the circuit's listing and the docs.
    initial : object
        What a delayed edge from this output delivers on the first pass (default None, delivered as is).
    optional : bool
        An output that may go nowhere; every other output needs an edge.
    """

    name: str
    dtype: str
    shape: tuple = ()
    doc: str = ""
    initial: object = None
    optional: bool = False

    def describe(self) -> str:
        return f"{self.dtype} shape {tuple(self.shape)}"

    def compatible(self, other: Signal) -> bool:
        """Same dtype and rank; fixed sizes equal; a named size matches the same name or any fixed size."""
        if self.dtype != other.dtype or len(self.shape) != len(other.shape):
            return False
        for a, b in zip(self.shape, other.shape):
            if isinstance(a, int) and isinstance(b, int) and a != b:
                return False
            if isinstance(a, str) and isinstance(b, str) and a != b:
                return False
        return True


@dataclass(frozen=True)
class Probe:
    """A recordable quantity. ``kind``: ``"float"``, ``"int"``, ``"bool"`` or
    ``"category"`` (stored as the index into ``categories``).

    Parameters
    ----------
    name : str
        The column's name in the recorded table.
    kind : str
        ``"float"``, ``"int"``, ``"bool"`` or ``"category"``.
    unit : str
        The value's unit (``""`` for none), for the docs and the figures.
    doc : str
        What the quantity is.
    categories : tuple of str
        A ``"category"`` probe's categories; the recorded value is an index into them.
    """

    name: str
    kind: str
    unit: str
    doc: str = ""
    categories: tuple[str, ...] = ()


@dataclass(frozen=True)
class NoParams:
    """Parameters of a region that has none."""

    def __post_init__(self):
        check_params(self)


class Region:
    """Base class of all regions. Subclasses are registered with ``@register(name)``; every region class
    takes the constructor's parameters below (its own ``Params`` class holds the model's parameters,
    docs/regions.md).

    Parameters
    ----------
    name : str
        The region's name in its circuit (default: the class name).
    params : Params, optional
        Its parameters, an instance of the class's ``Params``; or give them as keywords instead.
    **kwargs
        The parameters as keywords (``Params(**kwargs)``), when ``params`` is not given.
    """

    type_name: ClassVar[str] = ""
    Params: ClassVar[type] = NoParams
    inputs: ClassVar[tuple[Signal, ...]] = ()
    learn_inputs: ClassVar[tuple[Signal, ...]] = ()
    outputs: ClassVar[tuple[Signal, ...]] = ()
    probes: ClassVar[tuple[Probe, ...]] = ()
    frame_probes: tuple[Probe, ...] = ()
    lesions: ClassVar[dict[str, dict]] = {}
    #: The region that produces the episode: the scheduler counts frames from its ``n_frames``.
    is_clock: ClassVar[bool] = False
    #: The neuromodulator this region releases (``"da"``, ``"ne"``), or ``""``. A region that
    #: declares one accepts the drug lesions (clamp, scale, noise; docs/regions.md,
    #: "Pharmacology") and must pass every released level through :meth:`modulate` before
    #: using, emitting or recording it.
    modulator: ClassVar[str] = ""

    @classmethod
    def reads_reward(cls, params) -> bool:
        """Whether this region, with ``params``, makes its output from the world's extrinsic reward, so
        that in a world paying none it is degenerate (an experiment refuses it; docs/regions.md, VTA)."""
        return False

    def __init__(self, name: str = "", params=None, **kwargs):
        if params is not None and kwargs:
            raise ValueError("pass either a Params object or keyword parameters, not both")
        self.name = name or type(self).__name__
        self.params = params if params is not None else self.Params(**kwargs)
        if not isinstance(self.params, self.Params):
            raise ValueError(f"{type(self).__name__} expects params of type {self.Params.__name__}; "
                             f"got {type(self.params).__name__}")
        self.events: list[dict] = []
        #: Drugs applied to the released neuromodulator, in order (set by the circuit's lesions).
        self.drugs: tuple = ()
        #: The drugs' own random stream (noise), set by the simulator; separate from the region's.
        self.drug_rng: np.random.Generator | None = None
        #: The outputs some edge of the circuit reads, set by the simulator before :meth:`bind`;
        #: a region may leave an optional output that none reads uncomputed (NaN).
        self.wired: frozenset[str] = frozenset()

    def modulate(self, level: float) -> float:
        """The released neuromodulator ``level`` after this region's drugs (identity without any)."""
        for drug in self.drugs:
            level = drug.apply(level, self.drug_rng)
        return level

    @property
    def plastic(self) -> bool:
        """True when the region overrides :meth:`learn`."""
        return type(self).learn is not Region.learn

    def bind(self, world) -> None:
        """Take sizes from the world (number of contexts, states, pixels). Called once."""

    def reset(self, rng: np.random.Generator) -> None:
        """Start from scratch, drawing all randomness from ``rng``."""

    def step(self, *inputs) -> tuple:
        """Read ``inputs`` (in declared order) and return the outputs (in declared order)."""
        return ()

    def learn(self, *learn_inputs) -> None:
        """Plasticity, run after every region has stepped."""

    def record(self) -> tuple:
        """Values of ``probes`` for this pass, in order."""
        return ()

    def record_frames(self) -> np.ndarray:
        """A (T, len(frame_probes)) array of per-frame values for this pass."""
        return np.empty((0, 0))

    def products(self, events: pd.DataFrame) -> dict:
        """End-of-run products by name; ``events``: this region's events of the run
        (columns ``episode``, ``step``, ``region``, then the events' fields)."""
        return {}

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r}, params={self.params!r})"
