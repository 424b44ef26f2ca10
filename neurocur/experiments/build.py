"""The entrance's third pass: each :class:`~.expand.Plan` → a :class:`~.conditions.Condition`,
its circuit built once (the circuit file's tables as :mod:`.resolve` read them, the condition's
variant, the overrides, the lesions) and its world's parameters checked once (the world itself
is made per run, from these parameters).

Errors name the file (or ``--set``) and the key that wrote the value: a world key in the
table that set it, a ``"REGION.param"`` override where :mod:`.resolve` found it (a file's
``[params]``, the condition's own ``params``, the ``[sweep]``, or ``--set KEY``).
"""

from __future__ import annotations

import copy
from pathlib import Path

from neurocur.circuit import Circuit
from neurocur.circuit.files import add_tables
from neurocur.config import ConfigError, check_table, describe, make_params, resolve_paths
from neurocur.contexts import DEFAULT_WORLD, WORLDS
from neurocur.registry import UnknownType
from neurocur.tables import deep_merge

from .conditions import Condition, Experiment
from .expand import Plan
from .resolved import Entry, Resolved

__all__ = ["build", "check_reward_paid", "condition_world", "load_circuit"]


def build(resolved: Resolved, plans: list[Plan]) -> Experiment:
    """The experiment of ``resolved`` with the conditions of ``plans``, each built once.

    Parameters
    ----------
    resolved : Resolved
        The experiment file, its ``extends`` chain and the command line's settings (:mod:`.resolve`).
    plans : list of Plan
        Its conditions × sweep points ([`expand`][neurocur.experiments.expand.expand]).

    Returns
    -------
    Experiment
        The experiment, its conditions by label in the order of ``plans``.

    Raises
    ------
    ConfigError
        For a world or circuit key that fails its check, a ``fit`` key that is no parameter of the
        condition's circuit, or a reward-reading circuit on a world that pays none; naming the file and key.
    """
    conditions = {}
    for plan in plans:
        world, world_params = condition_world(plan.world, resolved.path)
        circuit = load_circuit(resolved.circuits[plan.condition.circuit], plan)
        for i, key in enumerate(plan.condition.fit):
            region, _, name = key.partition(".")
            if region not in circuit.specs or not hasattr(circuit.specs[region].params, name):
                raise ConfigError(plan.condition.source, f"conditions.{plan.condition.name}.fit[{i}]",
                                  "a REGION.param of the condition's circuit", repr(key))
        conditions[plan.label] = Condition(plan.label, plan.condition.circuit, plan.params, world, circuit,
                                           world_params, plan.condition.description, plan.point, plan.condition.fit)
        check_reward_paid(conditions[plan.label], plan.condition.source, plan.condition.name)
    return Experiment(name=resolved.name, path=resolved.path, description=resolved.description, runs=resolved.runs,
                      steps=resolved.steps, seed=resolved.seed, conditions=conditions, control=resolved.control)


def check_reward_paid(condition: Condition, source, name: str) -> None:
    """Refuse a condition whose circuit has a region that makes its output from the world's extrinsic
    reward (:meth:`~neurocur.regions.Region.reads_reward`: ``vta.td``, ``vta.mixture`` with a nonzero
    weight, ...) when its world pays none (:meth:`~neurocur.contexts.World.pays_reward`): such a run
    is silently degenerate (TD's DA is 0 on every episode, the decisions are ties). One line naming
    ``source``, ``world.rewards`` and the condition.

    Parameters
    ----------
    condition : Condition
        The built condition.
    source : path or str
        The file its ``[conditions]`` table is in (named by the error).
    name : str
        The condition's name in that file.

    Raises
    ------
    ConfigError
        When a region of the circuit reads the extrinsic reward and the world pays none.
    """
    readers = [f"{n} ({spec.type_name})" for n, spec in condition.circuit.specs.items() if spec.cls.reads_reward(spec.params)]
    if readers and not condition.world_class.pays_reward(condition.world_params):
        raise ConfigError(source, "world.rewards",
                          f"a world that pays an extrinsic reward (a nonzero entry; or a world type that pays, "
                          f"e.g. reward_blocks), since conditions.{name} has {', '.join(readers)}, which reads it",
                          "a world whose every visit pays 0")


def condition_world(layers: tuple[Entry, ...], source: Path):
    """The merged world table and its parameters, from world tables (each an :class:`~.resolved.Entry`
    whose key is the table's prefix: the file's ``[world]``, the condition's ``world``, a sweep
    point's, ``--set world.KEY``), later tables winning.

    The type comes from the last table that names one (:data:`~neurocur.contexts.DEFAULT_WORLD`
    when none does). Each table's keys are checked on their own (so an error names that
    table's key) and its paths made absolute against its folder; the merged table is then
    checked as a whole (``world.KEY`` errors, naming ``source``).

    Parameters
    ----------
    layers : tuple of Entry
        The world tables, the first losing to later ones.
    source : path
        The experiment file, named by the errors of the merged table (``world.KEY``).

    Returns
    -------
    (dict, object)
        The merged world table (with its ``type`` when a table named one) and the world type's checked ``Params``.

    Raises
    ------
    ConfigError
        For an unknown world type or a key that fails its check, naming the table that set it.
    """
    typed = [(e.value["type"], e.source, e.key) for e in layers if "type" in e.value]
    kind, type_source, type_prefix = typed[-1] if typed else (DEFAULT_WORLD, source, "world")
    try:
        cls = WORLDS.get(kind) if isinstance(kind, str) else None
    except UnknownType:
        cls = None
    if cls is None or cls.Params is None:
        raise ConfigError(type_source, f"{type_prefix}.type", f"a world type with parameters ({', '.join(WORLDS.names())})",
                          describe(kind))
    merged: dict = {}
    for layer in layers:
        body = resolve_paths(cls.Params, {k: v for k, v in layer.value.items() if k != "type"}, layer.here)
        check_table(cls.Params, body, source=layer.source, prefix=layer.key)
        merged = deep_merge(merged, body)
    params = make_params(cls.Params, merged, source=source, prefix="world")
    return {"type": kind, **merged} if typed else merged, params


_OVERRIDES = "<experiment overrides>"


def load_circuit(tables: dict, plan: Plan) -> Circuit:
    """The plan's circuit from its circuit file's ``tables``: the condition's ``replace``, ``edges``
    and ``lesion`` tables added as a file extending the circuit file would add them (each named
    ``conditions.NAME.replace.REGION``, ``conditions.NAME.edges[i]``, ``conditions.NAME.lesion[i]``),
    the overrides, the lesions, then the command line's ``REGION.param`` values, which win over
    all of them. An override's error names the file (or ``--set``) and key that wrote it.

    Parameters
    ----------
    tables : dict
        The circuit file's tables as :mod:`.resolve` read them (copied here, never changed).
    plan : Plan
        The condition at its sweep point: its variant tables, overrides and command-line values.

    Returns
    -------
    Circuit
        The condition's circuit, every value applied.

    Raises
    ------
    ConfigError
        For a value that fails its check, naming the file (or ``--set``) and key that wrote it.
    """
    condition = plan.condition
    data = copy.deepcopy(tables)
    overrides = {k: e.value for k, e in plan.overrides.items()}
    try:
        if condition.variant:
            add_tables(data, condition.variant, condition.source, f"conditions.{condition.name}.")
        circuit = Circuit.from_tables(data, condition.circuit, overrides=overrides, overrides_source=_OVERRIDES)
    except ConfigError as exc:
        raise _located(exc, plan.overrides, condition.source) from None
    try:
        return circuit.with_params({k: e.value for k, e in plan.set_params.items()}, source=_OVERRIDES)
    except ConfigError as exc:
        raise _located(exc, plan.set_params, f"--set {exc.key}") from None


def _located(exc: ConfigError, entries: dict[str, Entry], default_source) -> ConfigError:
    """``exc``, raised for one override, reported from the file (or ``--set``) and key that wrote it."""
    if exc.source != _OVERRIDES or exc.key is None:
        return exc
    entry = entries.get(exc.key)
    if entry is None:  # a check across parameters, naming one that was not overridden
        return ConfigError(default_source, None if str(default_source).startswith("--set") else f"params.{exc.key}",
                           exc.expected, exc.got)
    return ConfigError(entry.source, entry.key, exc.expected, exc.got)
