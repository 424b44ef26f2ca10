"""Building one condition of an experiment: its world table, and its circuit with the
overrides and lesions of the files that set them (:func:`neurocur.experiments.spec.load_experiment`).

Errors name the file (or ``--set``) and the key that wrote the value: a world key in the
layer that set it, a ``"REGION.param"`` override in the ``[params]`` of the file that set it
or in the condition's own ``params``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from neurocur.circuit import Circuit
from neurocur.circuit.files import add_tables, circuit_tables
from neurocur.config import ConfigError, check_table, describe, make_params, resolve_paths
from neurocur.contexts import WORLDS
from neurocur.registry import UnknownType
from neurocur.tables import deep_merge, require

__all__ = ["Overrides", "condition_world", "lesioned", "load_circuit"]


def condition_world(layers, source):
    """The merged world table and its parameters, from ``(table, source, prefix, base_dir)`` layers
    (the file's ``[world]``, the condition's ``world``, ``--set world.KEY``), later layers winning.

    The type comes from the last layer that names one. Each layer's keys are checked on
    their own (so an error names that layer's key) and its paths made absolute against
    its ``base_dir``; the merged table is then checked as a whole (``world.KEY`` errors).
    """
    typed = [(t["type"], s, p) for t, s, p, _ in layers if "type" in t]
    kind, type_source, type_prefix = typed[-1] if typed else ("synthetic", source, "world")
    try:
        cls = WORLDS.get(kind) if isinstance(kind, str) else None
    except UnknownType:
        cls = None
    if cls is None or cls.Params is None:
        raise ConfigError(type_source, f"{type_prefix}.type", f"a world type with parameters ({', '.join(WORLDS.names())})",
                          describe(kind))
    merged: dict = {}
    for table, layer_source, prefix, base_dir in layers:
        body = resolve_paths(cls.Params, {k: v for k, v in table.items() if k != "type"}, base_dir)
        check_table(cls.Params, body, source=layer_source, prefix=prefix)
        merged = deep_merge(merged, body)
    params = make_params(cls.Params, merged, source=source, prefix="world")
    return {"type": kind, **merged} if typed else merged, params


def lesioned(circuit: Circuit, tables, source, prefix: str) -> Circuit:
    """``circuit`` with a condition's lesions, each a table like a circuit file's ``[[lesion]]``
    (``region``, ``how``, and a drug's parameters)."""
    if not isinstance(tables, list):
        raise ConfigError(source, prefix, "an array of lesion tables (region, how, ...)", describe(tables))
    for i, table in enumerate(tables):
        key = f"{prefix}[{i}]"
        if not isinstance(table, dict):
            raise ConfigError(source, key, "a lesion table (region, how, ...)", describe(table))
        region = require(table, "region", str, source=source, prefix=key, expected="a region name (string)")
        how = require(table, "how", str, source=source, prefix=key, expected="a lesion name (string)")
        if region not in circuit.specs:
            raise ConfigError(source, f"{key}.region", f"a region of the circuit ({', '.join(circuit.specs)})",
                              describe(region))
        drug = {k: v for k, v in table.items() if k not in ("region", "how")}
        try:
            circuit = circuit.lesion(region, how, **drug)
        except ConfigError as exc:
            raise ConfigError(source, f"{key}{exc.key.removeprefix(f'lesion.{region}')}", exc.expected, exc.got) from None
    return circuit


@dataclass(frozen=True)
class Overrides:
    """A condition's ``"REGION.param"`` overrides and where each was written: the files'
    ``[params]`` (``origin``: key → file) and the condition's own (in ``source``)."""

    base: dict
    origin: dict
    condition: dict
    source: Path
    name: str

    def locate(self, exc: ConfigError) -> ConfigError:
        """``exc``, raised for one override, reported from the file and key that set it."""
        if exc.key in self.condition:
            return ConfigError(self.source, f"conditions.{self.name}.params.{exc.key}", exc.expected, exc.got)
        return ConfigError(self.origin.get(exc.key, self.source), f"params.{exc.key}", exc.expected, exc.got)


_OVERRIDES = "<experiment overrides>"


def load_circuit(circuit: Path, overrides: Overrides, set_params: dict, variant: dict | None = None) -> Circuit:
    """The condition's circuit with its overrides; errors name the file (or --set) and key.

    ``variant``: the condition's own ``replace`` and ``edges`` tables, added to the circuit
    file's as a file extending it would add them (so before the overrides and the file's
    lesions), each named ``conditions.NAME.replace.REGION`` or ``conditions.NAME.edges[i]``."""
    try:
        path, data = circuit_tables(circuit)
        if variant:
            add_tables(data, variant, overrides.source, f"conditions.{overrides.name}.")
        loaded = Circuit.from_tables(data, path, overrides={**overrides.base, **overrides.condition},
                                     overrides_source=_OVERRIDES)
    except ConfigError as exc:
        if exc.source == _OVERRIDES and exc.key is not None:
            raise overrides.locate(exc) from None
        raise
    try:
        return loaded.with_params(set_params, source="--set")
    except ConfigError as exc:
        raise ConfigError(f"--set {exc.key}", None, exc.expected, exc.got) from None
