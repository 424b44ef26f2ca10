"""Circuits: regions wired by signal edges, declared in TOML, validated and ordered once.

A circuit file declares regions and edges::

    [regions.VTA]
    type = "vta.learning_progress"          # a registered region type
    params = { boredom = -100.0 }

    [[edges]]
    from = "HPC"                             # producing region
    signal = "familiar"                      # one of its outputs
    to = "VTA"                               # consuming region
    # input = "familiar"                     # the consumer's input (default: same name)
    # delayed = true                         # read the previous pass's value

A variant file ``extends = "cd_misfa.toml"`` (a path relative to itself, or the name of a
circuit shipped with the package, ``extends = "cd_misfa"``) and adds
``[[lesion]]`` tables (``region``, ``how``), ``[replace.NAME]`` tables (``type``,
``params``), ``[regions.NAME.params]`` overrides or more edges. A lesion is one of the
region type's named lesions (parameter overrides, e.g. ``how = "random"`` for the LC) or,
for a region that releases a neuromodulator, a drug with its parameters in the same table
(``how = "clamp"``, ``level = 4.0``; :mod:`neurocur.regions.pharmacology`).

Semantics (one scheduler pass = one episode):

- step phase, in topological order of the *step graph*: the edges into step inputs
  that are not delayed. A delayed edge delivers the previous pass's value (the
  output's ``initial`` on the first pass), so it may close a loop;
- learn phase, after every step: edges into ``learn_inputs`` deliver this pass's
  values and never constrain the order, so a later region may gate an earlier one's
  learning without a cycle;
- a step-graph cycle without a delayed edge is a build error naming the cycle.

**Names and paths.** Wherever a circuit is named (``Circuit.from_toml``, ``extends``, an
experiment's ``circuit``), a value that is an existing path, ends with ``.toml`` or
contains a path separator is a path; any other value is the name of a circuit shipped in
the package (``neurocur/circuits/NAME.toml``, :func:`~neurocur.tables.shipped_files`), found with
:mod:`importlib.resources` so that it works from an installed wheel. An unknown name is a
ConfigError listing the shipped names.

Validation errors are :class:`~neurocur.config.ConfigError` naming the file and key.
"""

from __future__ import annotations

from collections.abc import Mapping

import networkx as nx

from ..config import ConfigError, describe, params_to_dict
from ..regions import Region
from .files import circuit_tables
from .specs import (
    PY,
    Link,
    RegionSpec,
    apply_overrides,
    input_ports,
    lesioned,
    link_between,
    link_from_table,
    ports,
    spec_from_table,
)

__all__ = ["Circuit", "RegionSpec", "Link"]


class Circuit:
    """A validated, ordered circuit of regions. Immutable: lesions and replacements return new circuits.

    Parameters
    ----------
    regions : mapping of str to RegionSpec
        The regions by name.
    links : sequence of Link
        The edges: source output to destination input, delayed or not.
    source : str
        The file named in a message.
    lesions : sequence, optional
        The lesions applied (recorded with the circuit).
    """

    def __init__(self, regions, links, *, source: str = PY, lesions=()):
        self.source = str(source)
        self.specs: dict[str, RegionSpec] = dict(regions)
        self.links: tuple[Link, ...] = tuple(links)
        #: ``(region, how, drug parameters)`` of every lesion applied, in order.
        self.lesions: tuple[tuple[str, str, dict], ...] = tuple(lesions)
        self.graph = nx.DiGraph()
        self._validate()

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_toml(cls, path, overrides: Mapping | None = None, *, overrides_source: str = "overrides") -> Circuit:
        """Load a circuit file (following ``extends``); ``overrides`` maps ``"REGION.param"`` to a value.

        ``path`` is a file path or the name of a shipped circuit (``"cd_misfa"``, :func:`~neurocur.tables.shipped_files`)."""
        path, data = circuit_tables(path)
        return cls.from_tables(data, path, overrides, overrides_source=overrides_source)

    @classmethod
    def from_tables(cls, data: Mapping, source, overrides: Mapping | None = None, *,
                    overrides_source: str = "overrides") -> Circuit:
        """The circuit of a circuit file's tables as :func:`~neurocur.circuit.files.read_circuit_file`
        reads them (and :func:`~neurocur.circuit.files.add_tables` adds to them): regions, then
        their replacements, the overrides, the lesions; ``source`` names the circuit."""
        regions = {}
        for name, table in data["regions"].items():
            regions[name] = spec_from_table(name, table, prefix=f"regions.{name}")
        for name, table in data["replace"].items():
            key = table["_key"]
            if name not in regions:
                raise ConfigError(table["_origin"], key, f"the name of a declared region ({', '.join(regions)})",
                                  "an unknown region")
            regions[name] = spec_from_table(name, table, prefix=key)
        links = [link_from_table(t) for t in data["edges"]]
        regions = apply_overrides(regions, overrides or {}, overrides_source)
        lesions = []
        for table in data["lesion"]:
            name, how = table["region"], table["how"]
            if name not in regions:
                raise ConfigError(table["_origin"], f"{table['_key']}.region", f"a declared region ({', '.join(regions)})",
                                  describe(name))
            drug = {k: v for k, v in table.items() if k not in ("region", "how") and not k.startswith("_")}
            regions[name] = lesioned(regions[name], how, drug, source=table["_origin"], key=table["_key"])
            lesions.append((name, how, drug))
        return cls(regions, links, source=source, lesions=lesions)

    def lesion(self, name: str, how: str, **drug) -> Circuit:
        """A new circuit with region ``name`` lesioned: ``how`` is one of its class's ``lesions``,
        or, for a region with a ``modulator``, a drug (``"clamp"``, ``"scale"``, ``"noise"``)
        with its parameters as keywords (``circuit.lesion("LC", "clamp", level=4.0)``)."""
        self._check_region(name)
        specs = dict(self.specs)
        specs[name] = lesioned(specs[name], how, drug, source=PY, key=f"lesion.{name}")
        return Circuit(specs, self.links, source=self.source, lesions=self.lesions + ((name, how, drug),))

    def replace(self, name: str, region, *, drop_edges: bool = False, inputs: Mapping[str, str] | None = None) -> Circuit:
        """A new circuit with region ``name`` replaced by a Region object or a spec mapping
        ``{"type": "vta.novelty", "params": {...}}``.

        ``inputs`` maps inputs of the new region to the outputs that feed them,
        ``{"progress": "EC.slowness_progress"}``: an input the old region did not have needs one,
        and one it had is rewired (what ``[[edges]]`` add in a variant circuit file). An edge into
        an input, or out of an output, that the new region does not have is an error naming it;
        with ``drop_edges=True`` such edges are dropped (e.g. HPC's ``progress`` when
        ``vta.state_progress`` is replaced by a model that does not read it)."""
        self._check_region(name)
        specs = dict(self.specs)
        if isinstance(region, Region):
            specs[name] = RegionSpec(name, type(region), region.params, instance=region)
        elif isinstance(region, Mapping):
            table = dict(region)
            table["_origin"] = PY
            specs[name] = spec_from_table(name, table, prefix=f"replace.{name}")
        else:
            raise ValueError(f"replace() expects a Region object or a mapping with 'type' and 'params'; "
                             f"got {type(region).__name__}")
        new = [link_between(src, f"{name}.{inp}", key=f"replace.{name}.inputs.{inp}")
               for inp, src in (inputs or {}).items()]
        fed = {(k.dst, k.input) for k in new}
        kept = [k for k in self.links if (k.dst, k.input) not in fed]
        ins = {s.name for s in input_ports(specs[name])}
        outs = {s.name for s in ports(specs[name], "outputs")}
        stale = [k for k in kept if (k.dst == name and k.input not in ins) or (k.src == name and k.signal not in outs)]
        if stale and not drop_edges:
            raise ConfigError(PY, f"replace.{name}",
                              f"a region with a port for every edge of '{name}', or drop_edges=True to drop the others",
                              f"{specs[name].type_name}, which has no port for {', '.join(map(str, stale))}")
        return Circuit(specs, [k for k in kept if k not in stale] + new, source=self.source, lesions=self.lesions)

    def connect(self, source: str, target: str, *, delayed: bool = False) -> Circuit:
        """A new circuit with the edge ``source -> target``, named ``"REGION.output"`` and
        ``"REGION.input"`` (``circuit.connect("HPC.progress", "VTA.progress")``): what a
        ``[[edges]]`` table adds in a circuit file. An edge already into ``target`` is replaced in
        place (the output it came from must then be read elsewhere, or be optional);
        ``delayed=True`` delivers the previous pass's value, so the edge may close a loop."""
        link = link_between(source, target, delayed=delayed, key="connect")
        into = (link.dst, link.input)
        links = [link if (k.dst, k.input) == into else k for k in self.links]
        if link not in links:
            links.append(link)
        return Circuit(self.specs, links, source=self.source, lesions=self.lesions)

    def with_params(self, overrides: Mapping, *, source: str = "overrides") -> Circuit:
        """A new circuit with ``"REGION.param"`` overrides applied."""
        return Circuit(apply_overrides(self.specs, overrides, source), self.links, source=self.source,
                       lesions=self.lesions)

    def build(self, world, seed, record_frames: bool = False):
        """A ready-to-run :class:`~neurocur.scheduler.Simulator` on ``world``."""
        from ..scheduler import Simulator

        return Simulator(self, world, seed, record_frames=record_frames)

    # ------------------------------------------------------------------ inspection

    def to_dict(self) -> dict:
        """The fully resolved circuit (lesions folded into the parameters) as plain data."""
        return {
            "regions": {name: {"type": s.type_name, "params": params_to_dict(s.params)} for name, s in self.specs.items()},
            "edges": [
                {"from": k.src, "signal": k.signal, "to": k.dst, "input": k.input, "delayed": k.delayed}
                for k in self.links
            ],
            "lesions": [{"region": r, "how": h, **drug} for r, h, drug in self.lesions],
        }

    def schedule(self) -> str:
        """Printable text: step order, learn order, delayed edges and learn-phase edges."""
        lines = ["step order:"]
        for i, name in enumerate(self.step_order, 1):
            s = self.specs[name]
            ins = ", ".join(
                f"{k.input}<-{k.src}.{k.signal}{' (delayed)' if k.delayed else ''}"
                for k in self.links if k.dst == name and k.input in self._step_inputs(name))
            lines.append(f"  {i}. {name} [{s.type_name}]" + (f"  reads {ins}" if ins else ""))
        lines.append("learn order: " + (", ".join(self.learn_order) or "(none)"))
        lines.append("delayed edges (previous pass):")
        lines += [f"  {k}" for k in self.links if k.delayed] or ["  (none)"]
        lines.append("learn-phase edges (this pass, after all steps):")
        lines += [f"  {k}" for k in self.links if not k.delayed and k.input not in self._step_inputs(k.dst)] or ["  (none)"]
        if self.lesions:
            lines.append("lesions: " + ", ".join(f"{r} ({h}{''.join(f', {k}={v}' for k, v in d.items())})"
                                                 for r, h, d in self.lesions))
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"Circuit({self.source!r}, regions={list(self.specs)})"

    # ------------------------------------------------------------------ validation

    def _check_region(self, name):
        if name not in self.specs:
            raise ValueError(f"no region named {name!r} in this circuit (regions: {', '.join(self.specs)})")

    def _declared(self, spec: RegionSpec) -> tuple[str, str]:
        """The file and key that declared ``spec``, for its errors."""
        return (spec.origin if spec.origin != PY else self.source), spec.key or f"regions.{spec.name}"

    def _step_inputs(self, name) -> dict:
        return {s.name: s for s in ports(self.specs[name], "inputs")}

    def _validate(self) -> None:
        specs, src = self.specs, self.source
        if not specs:
            raise ConfigError(src, "regions", "at least one region", "none")
        for name, spec in specs.items():
            self.graph.add_node(name, type=spec.type_name, params=spec.params)
        fed: dict[tuple[str, str], Link] = {}
        used_outputs = set()
        for link in self.links:
            for end, field_ in ((link.src, "from"), (link.dst, "to")):
                if end not in specs:
                    raise ConfigError(link.origin, f"{link.key}.{field_}", f"a declared region ({', '.join(specs)})",
                                      describe(end))
            outs = {s.name: s for s in ports(specs[link.src], "outputs")}
            if link.signal not in outs:
                raise ConfigError(link.origin, f"{link.key}.signal", f"an output of region '{link.src}' ({', '.join(outs) or 'none'})",
                                  describe(link.signal))
            ins = {s.name: s for s in input_ports(specs[link.dst])}
            if link.input not in ins:
                raise ConfigError(link.origin, f"{link.key}.input", f"an input of region '{link.dst}' ({', '.join(ins) or 'none'})",
                                  describe(link.input))
            out_sig, in_sig = outs[link.signal], ins[link.input]
            if not out_sig.compatible(in_sig):
                raise ConfigError(link.origin, link.key,
                                  f"{link.dst}.{link.input} as {in_sig.describe()}",
                                  f"{link.src}.{link.signal} as {out_sig.describe()}")
            if (link.dst, link.input) in fed:
                raise ConfigError(link.origin, link.key, f"a single edge into input '{link.dst}.{link.input}'",
                                  f"a second one (the first is {fed[(link.dst, link.input)]})")
            fed[(link.dst, link.input)] = link
            used_outputs.add((link.src, link.signal))
            if self.graph.has_edge(link.src, link.dst):
                self.graph.edges[link.src, link.dst]["links"].append(link)
            else:
                self.graph.add_edge(link.src, link.dst, links=[link])
        for name, spec in specs.items():
            for sig in input_ports(spec):
                if (name, sig.name) not in fed:
                    raise ConfigError(*self._declared(spec), f"an edge into its input '{sig.name}' ({sig.describe()})",
                                      "no edge")
            for sig in ports(spec, "outputs"):
                if not sig.optional and (name, sig.name) not in used_outputs:
                    raise ConfigError(*self._declared(spec), f"an edge from its output '{sig.name}' ({sig.describe()})",
                                      "an output that goes nowhere")
        recorded = {"episode": "the scheduler", "step": "the scheduler"}
        for name, spec in specs.items():
            for probe in ports(spec, "probes"):
                if probe.name in recorded:
                    raise ConfigError(*self._declared(spec),
                                      f"probe names unique in the circuit ('{probe.name}' is recorded by "
                                      f"{recorded[probe.name]})", f"a second probe '{probe.name}'")
                recorded[probe.name] = f"region '{name}'"
        step_graph = nx.DiGraph()
        step_graph.add_nodes_from(specs)
        for link in self.links:
            if not link.delayed and link.input in self._step_inputs(link.dst):
                step_graph.add_edge(link.src, link.dst)
        try:
            cycle = nx.find_cycle(step_graph, source=list(specs))
        except nx.NetworkXNoCycle:
            cycle = None
        if cycle:
            names = [u for u, _ in cycle] + [cycle[0][0]]
            raise ConfigError(src, "edges", "a delayed = true edge on every loop of step inputs",
                              f"cycle {' -> '.join(names)} has no delayed edge")
        rank = {name: i for i, name in enumerate(specs)}
        self.step_order: tuple[str, ...] = tuple(nx.lexicographical_topological_sort(step_graph, key=rank.__getitem__))
        self.learn_order: tuple[str, ...] = tuple(n for n in self.step_order if specs[n].cls.learn is not Region.learn)
