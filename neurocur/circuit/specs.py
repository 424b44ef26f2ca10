"""The parts of a circuit: declared regions (:class:`RegionSpec`) and edges (:class:`Link`), and
making them from the tables of a circuit file or from Python (parameters, overrides, lesions).

The circuit file format and the meaning of its tables are described in :mod:`neurocur.circuit`;
:class:`~neurocur.circuit.Circuit` validates the whole.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

from ..config import ConfigError, describe, make_params, params_to_dict
from ..regions import REGIONS, Region
from ..regions.pharmacology import DRUGS
from ..registry import UnknownType
from ..tables import check_keys, require

__all__ = ["PY", "Link", "RegionSpec", "apply_overrides", "input_ports", "lesioned", "link_between",
           "link_from_table", "ports", "spec_from_table"]

PY = "<python>"


@dataclass(frozen=True)
class RegionSpec:
    """A declared region: its class and parameters, or a prebuilt (not yet reset) instance,
    and the drugs acting on its neuromodulator (:mod:`neurocur.regions.pharmacology`);
    ``origin`` and ``key``: the file and table that declared it (``regions.NAME``,
    ``replace.NAME``, ``conditions.C.replace.NAME``), which its errors name.

    Parameters
    ----------
    name : str
        The region's name.
    cls : type
        Its class.
    params : object
        Its parameters (an instance of ``cls.Params``).
    instance : Region, optional
        A prebuilt region, not yet reset.
    origin : str
        The file that declared it.
    drugs : tuple
        The drugs on its neuromodulator.
    key : str, optional
        The table that declared it.
    """

    name: str
    cls: type
    params: object
    instance: Region | None = None
    origin: str = PY
    drugs: tuple = ()
    key: str | None = None

    @property
    def type_name(self) -> str:
        return self.cls.type_name or self.cls.__qualname__

    def make(self) -> Region:
        if self.instance is not None:
            region = copy.deepcopy(self.instance)
            region.name = self.name
        else:
            region = self.cls(self.name, self.params)
        region.drugs = self.drugs
        return region


@dataclass(frozen=True)
class Link:
    """One edge: ``src.signal -> dst.input``.

    Parameters
    ----------
    src : str
        The source region.
    signal : str
        Its output.
    dst : str
        The destination region.
    input : str
        Its input.
    delayed : bool
        The edge delivers the previous pass's value (its signal's ``initial`` on the first).
    origin : str
        The file that declared it.
    key : str
        The table that declared it.
    """

    src: str
    signal: str
    dst: str
    input: str
    delayed: bool = False
    origin: str = PY
    key: str = "edges"

    def __str__(self) -> str:
        return f"{self.src}.{self.signal} -> {self.dst}.{self.input}"


def ports(spec: RegionSpec, kind: str):
    """The declared signals of a region; instance-level when they depend on parameters.

    Parameters
    ----------
    spec : RegionSpec
        The region.
    kind : str
        ``"inputs"``, ``"learn_inputs"``, ``"outputs"`` or ``"probes"``.

    Returns
    -------
    tuple of Signal or Probe
        The signals.
    """
    holder = spec.instance if spec.instance is not None else spec.cls
    value = getattr(holder, kind)
    if isinstance(value, property) or callable(value):  # parameter-dependent ports
        value = getattr(spec.make(), kind)
    return tuple(value)


def input_ports(spec: RegionSpec) -> tuple:
    """Every input a region declares: those its step reads, then those its learn phase reads.

    Parameters
    ----------
    spec : RegionSpec
        The region.

    Returns
    -------
    tuple of Signal
        Its inputs.
    """
    return ports(spec, "inputs") + ports(spec, "learn_inputs")


def spec_from_table(name: str, table: Mapping, *, prefix: str) -> RegionSpec:
    """The region a circuit file's table declares: its registered ``type`` and its ``params`` table,
    checked against the class's ``Params``; errors are ConfigErrors naming the file and ``prefix``'s keys.

    Parameters
    ----------
    name : str
        The region's name in the circuit.
    table : mapping
        The region's table (``type``, optional ``params``) with ``_origin``, the file that declared it
        (keys starting with ``_`` are the reader's, not the file's).
    prefix : str
        The table's key (``regions.NAME``, ``replace.NAME``), named in a message and kept as the
        spec's ``key``.

    Returns
    -------
    RegionSpec
        The declared region.
    """
    origin = table["_origin"]
    body = {k: v for k, v in table.items() if not k.startswith("_")}
    check_keys(body, ("type", "params"), source=origin, prefix=prefix, required=("type",))
    type_name = require(body, "type", str, source=origin, prefix=prefix, expected="a region type name (string)")
    try:
        cls = REGIONS.get(type_name)
    except UnknownType:
        raise ConfigError(origin, f"{prefix}.type", f"a registered region type ({', '.join(REGIONS.names())})",
                          describe(type_name)) from None
    params_table = require(body, "params", dict, source=origin, prefix=prefix, expected="a table of parameters",
                           default={})
    params = make_params(cls.Params, params_table, source=origin, prefix=f"{prefix}.params")
    return RegionSpec(name, cls, params, origin=origin, key=prefix)


def link_from_table(table: Mapping) -> Link:
    """The edge an ``[[edges]]`` table declares: ``from``, ``signal``, ``to`` and optionally ``input``
    (default: the signal's name) and ``delayed`` (default false); errors are ConfigErrors naming the
    file and the table's key.

    Parameters
    ----------
    table : mapping
        The edge's table with ``_origin`` and ``_key``, the file and the key that declared it (keys
        starting with ``_`` are the reader's, not the file's).

    Returns
    -------
    Link
        The edge.
    """
    origin, key = table["_origin"], table["_key"]
    body = {k: v for k, v in table.items() if not k.startswith("_")}
    check_keys(body, ("from", "to", "signal", "input", "delayed"), source=origin, prefix=key,
               required=("from", "to", "signal"))
    words = {f: require(body, f, str, source=origin, prefix=key, expected="a name (string)") for f in ("from", "to", "signal")}
    inp = require(body, "input", str, source=origin, prefix=key, expected="an input name (string)", default=words["signal"])
    delayed = require(body, "delayed", bool, source=origin, prefix=key, expected="true or false", default=False)
    return Link(words["from"], words["signal"], words["to"], inp, delayed, origin=origin, key=key)


def link_between(source: str, target: str, *, delayed: bool = False, key: str) -> Link:
    """The edge ``source -> target`` given from Python as ``"REGION.output"`` and ``"REGION.input"``;
    a malformed name is a ConfigError at ``key``. Whether the ports exist is checked by the circuit.

    Parameters
    ----------
    source : str
        ``"REGION.output"``.
    target : str
        ``"REGION.input"``.
    delayed : bool
        A delayed edge.
    key : str
        The key named in a message.

    Returns
    -------
    Link
        The edge.
    """
    ends = []
    for value, what in ((source, "an output"), (target, "an input")):
        region, dot, port = str(value).partition(".")
        if not (isinstance(value, str) and region and dot and port):
            raise ConfigError(PY, key, f"'REGION.port' naming {what}", describe(value))
        ends.append((region, port))
    (src, signal), (dst, inp) = ends
    return Link(src, signal, dst, inp, bool(delayed), origin=PY, key=key)


def apply_overrides(specs: Mapping[str, RegionSpec], overrides: Mapping, source) -> dict[str, RegionSpec]:
    """``specs`` with parameter overrides: each region's parameters merged with its overrides and
    checked again by its ``Params`` (a prebuilt instance gets a copy with the new parameters).

    Parameters
    ----------
    specs : mapping of str to RegionSpec
        The regions by name.
    overrides : mapping
        ``{"REGION.param": value}``; an unknown region, a key without a dot or a bad value is a
        ConfigError.
    source : str
        Where the overrides came from, named in a message.

    Returns
    -------
    dict of str to RegionSpec
        The regions by name, those without overrides unchanged.
    """
    specs = dict(specs)
    grouped: dict[str, dict] = {}
    for dotted, value in overrides.items():
        name, dot, pname = str(dotted).partition(".")
        if not dot or name not in specs:
            raise ConfigError(source, str(dotted), f"'REGION.param' with REGION one of {', '.join(specs)}",
                              "an unknown region" if dot else "no dot")
        grouped.setdefault(name, {})[pname] = value
    for name, table in grouped.items():
        spec = specs[name]
        merged = {**params_to_dict(spec.params), **table}
        params = make_params(spec.cls.Params, merged, source=source, prefix=name)
        specs[name] = dataclasses.replace(spec, params=params, instance=None if spec.instance is None else
                                          with_params(spec.instance, params))
    return specs


def with_params(instance: Region, params) -> Region:
    region = copy.deepcopy(instance)
    region.params = params
    return region


def lesioned(spec: RegionSpec, how, drug: Mapping, *, source, key) -> RegionSpec:
    """``spec`` with the lesion ``how``: a named lesion of its class (parameter overrides,
    no further keys) or a drug on its neuromodulator (``drug`` holds the drug's parameters).

    Parameters
    ----------
    spec : RegionSpec
        The region.
    how : str
        A named lesion of its class, or a drug (``clamp``, ``scale``, ``noise``).
    drug : mapping
        The drug's parameters.
    source : str
        The file named in a message.
    key : str
        The key named in a message.

    Returns
    -------
    RegionSpec
        The lesioned region.
    """
    options = dict(spec.cls.lesions)
    if spec.cls.modulator:
        options.update({name: f"drug on {spec.cls.modulator}" for name in DRUGS})
    if how not in options:
        raise ConfigError(source, f"{key}.how", f"a lesion of {spec.type_name} ({', '.join(options) or 'none defined'})",
                          describe(how))
    if how in spec.cls.lesions:
        if drug:
            raise ConfigError(source, f"{key}.{next(iter(drug))}", f"no further keys for the lesion '{how}' "
                              "(it sets the region's parameters)", "a key")
        params = dataclasses.replace(spec.params, **spec.cls.lesions[how])
        instance = None if spec.instance is None else with_params(spec.instance, params)
        return dataclasses.replace(spec, params=params, instance=instance)
    made = make_params(DRUGS[how], drug, source=source, prefix=key)
    return dataclasses.replace(spec, drugs=spec.drugs + (made,))
