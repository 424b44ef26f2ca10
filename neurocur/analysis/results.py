"""A results folder as the analysis reads it: :class:`Results` (tables, sources, experiment config).

Every statistic and figure that needs more than one table takes a :class:`Results`: the
episodes and modules tables, the sources each condition's world showed
(:class:`~neurocur.contexts.base.SourceSpec`, read from each condition's first ``run.json``)
and the folder's ``config.toml`` (the resolved experiment). What the analysis needs to know
about the experiment is read from there, never from a condition's or a region's name:

- :attr:`Results.reference` — the condition the others are compared against: the first
  condition of the experiment file;
- :attr:`Results.control` — the experiment's declared control condition (the experiment
  file's top-level ``control`` key), or None;
- :meth:`Results.region_param` — a parameter of the region of a given type in each
  condition's resolved circuit (e.g. eq 14's ``alpha`` of the value estimator,
  :class:`~neurocur.regions.pfc.PFCLSPI`), whatever the circuit calls that region;
- :attr:`Results.world_types` — the world types of the conditions, which pick the folder's
  figure set (:mod:`neurocur.analysis.figures.sets`).
- :meth:`Results.probe_docs` — what each recorded column of a condition is, from the probes of
  the region types of its resolved circuit (the figures' captions).

Tables built in memory (tests, notebooks) are wrapped with :meth:`Results.of`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from neurocur.contexts import DEFAULT_WORLD
from neurocur.contexts.base import SourceSpec
from neurocur.regions import REGIONS
from neurocur.registry import UnknownType
from neurocur.results import ResultsStore

__all__ = ["Results", "source_specs"]


def source_specs(results_dir: str | Path) -> dict[str, SourceSpec]:
    """Each condition's :class:`~neurocur.contexts.base.SourceSpec`, read from its first run's
    ``run.json``; conditions in the order of the folder's ``config.toml``, then the others.

    Parameters
    ----------
    results_dir : str or path
        The results folder.

    Returns
    -------
    dict of str to SourceSpec
        By condition.
    """
    store = ResultsStore(results_dir)
    specs: dict[str, SourceSpec] = {}
    for path in store.run_dirs():
        condition = path.parent.name
        if condition not in specs:
            info = store.run_info(path)
            specs[condition] = SourceSpec(tuple(c["name"] for c in info["contexts"]),
                                          tuple(c["source"] for c in info["contexts"]), tuple(info["learnable"]))
    order = list((store.config() or {}).get("conditions", {}))
    return {c: specs[c] for c in sorted(specs, key=lambda c: (order.index(c) if c in order else len(order), c))}


@dataclass(frozen=True)
class Results:
    """The episodes and modules tables of a results folder, each condition's sources and its config.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The episodes table of every run.
    modules : pandas.DataFrame
        The modules table of every run.
    specs : mapping of str to SourceSpec
        Each condition's world's :class:`SourceSpec`, in the order of the experiment (the reference first).
    config : mapping
        The folder's ``config.toml`` (empty for tables built in memory).
    path : path, optional
        The folder (None in memory).
    """

    episodes: pd.DataFrame
    modules: pd.DataFrame
    specs: Mapping[str, SourceSpec]
    config: Mapping = field(default_factory=dict)
    path: Path | None = None

    @classmethod
    def load(cls, results_dir: str | Path, *, tables: tuple[pd.DataFrame, pd.DataFrame] | None = None) -> Results:
        """Read a results folder; ``tables``: its ``(episodes, modules)`` when already loaded."""
        store = ResultsStore(results_dir)
        episodes, modules = store.load() if tables is None else tables
        return cls(episodes, modules, source_specs(results_dir), store.config() or {}, Path(results_dir))

    @classmethod
    def of(cls, episodes: pd.DataFrame, modules: pd.DataFrame, spec: SourceSpec | Mapping[str, SourceSpec],
           config: Mapping | None = None) -> Results:
        """Tables built in memory: ``spec`` is every condition's sources, or one per condition."""
        if isinstance(spec, SourceSpec):
            names = list(dict.fromkeys([*episodes["condition"], *modules["condition"]]))
            spec = dict.fromkeys(names, spec)
        return cls(episodes, modules, dict(spec), config or {})

    @property
    def conditions(self) -> list[str]:
        """The conditions of the episodes table, in name order."""
        return sorted(self.episodes["condition"].unique())

    @property
    def spec(self) -> SourceSpec:
        """The sources of every condition's world; ValueError when the conditions' worlds differ."""
        specs = {self.spec_of(c) for c in self.conditions} or set(self.specs.values())
        if len(specs) != 1:
            raise ValueError(f"the conditions' worlds show different sources ({len(specs)} kinds); "
                             "select conditions of one world (Results.select)")
        return specs.pop()

    def spec_of(self, condition: str) -> SourceSpec:
        """The sources of ``condition``'s world."""
        if condition not in self.specs:
            raise ValueError(f"no source spec for condition {condition!r}; have {sorted(self.specs)}")
        return self.specs[condition]

    def select(self, conditions) -> Results:
        """The same results, only for ``conditions``."""
        keep = list(conditions)
        return Results(self.episodes[self.episodes["condition"].isin(keep)],
                       self.modules[self.modules["condition"].isin(keep)],
                       {c: s for c, s in self.specs.items() if c in keep}, self.config, self.path)

    @property
    def reference(self) -> str | None:
        """The condition compared against the others: the experiment's first condition
        (``config.toml``'s order; in memory, the first of ``specs``)."""
        return next(iter(self.config.get("conditions", self.specs)), None)

    @property
    def control(self) -> str | None:
        """The experiment's declared control condition (its ``control`` key), or None."""
        return self.config.get("control")

    @property
    def world_tables(self) -> dict[str, dict]:
        """Each condition's resolved ``[world]`` table in ``config.toml``."""
        return {name: c.get("world", {}) for name, c in self.config.get("conditions", {}).items()}

    @property
    def world_types(self) -> set[str]:
        """The world types (``world.type``) of the conditions in ``config.toml``."""
        return {world.get("type", DEFAULT_WORLD) for world in self.world_tables.values()}

    def region_param(self, kind: type, key: str) -> dict[str, object]:
        """``key`` of the region of type ``kind`` (a region class, or a subclass of it) in each
        condition's resolved circuit; the parameter's default when ``config.toml`` records none.
        A condition whose circuit has no such region, or several, is left out."""
        out = {}
        for name, condition in self.config.get("conditions", {}).items():
            found = [region for region in condition.get("resolved_circuit", {}).get("regions", {}).values()
                     if _is_a(region.get("type"), kind)]
            if len(found) == 1:
                params = found[0].get("params", {})
                out[name] = params[key] if key in params else getattr(kind.Params(), key)
        return out

    def probe_docs(self, condition: str) -> dict[str, str]:
        """What each recorded column of ``condition``'s episodes table is, by column: the
        ``doc`` and ``unit`` of the probe (:class:`~neurocur.regions.base.Probe`) of the region
        type that records it in the condition's resolved circuit, e.g. ``{"ne_phasic":
        "event-locked burst (1 at module storage, engage advantage) [[0, 1]]"}``; empty when
        ``config.toml`` records no circuit (tables in memory) or a region type is not installed."""
        regions = self.config.get("conditions", {}).get(condition, {}).get("resolved_circuit", {}).get("regions", {})
        docs = {}
        for region in regions.values():
            try:
                kind = REGIONS.get(region.get("type"))
            except UnknownType:
                continue
            for probe in getattr(kind, "probes", ()):
                if probe.doc:
                    unit = probe.unit if probe.unit.startswith("[") else f"[{probe.unit}]"
                    docs[probe.name] = f"{probe.doc} {unit}" if probe.unit else probe.doc
        return docs


def _is_a(type_name, kind: type) -> bool:
    try:
        return isinstance(type_name, str) and issubclass(REGIONS.get(type_name), kind)
    except UnknownType:
        return False
