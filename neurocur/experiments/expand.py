"""The entrance's second pass: a :class:`~.resolved.Resolved` experiment → its conditions × sweep
points, each a :class:`Plan` that :mod:`.build` makes. Pure: nothing is read here, and only the
names that become folders are checked (:mod:`neurocur.results.names`).

An experiment file may sweep parameters of the circuit (``"REGION.param"``) and of the
world (``"world.KEY"``, or a nested ``"world.TABLE.KEY"``)::

    [sweep]
    "LC.gain" = [0.5, 1.0, 2.0]
    "world.normalise" = ["global", "image"]

Every condition is run at every point of the product (here 3 × 2 = 6 points), each as
its own condition named ``<condition>@<KEY>=<value>,<KEY>=<value>`` (keys sorted:
:func:`neurocur.results.names.condition_label`, which checks the condition's name and that no
two points share a label, before anything runs); run *i* of every
condition and point uses the same seed (paired). Each swept key is a column of every
results table. ``--set KEY=V1,V2`` replaces a key's values (a single value restricts the
sweep to it) or adds a swept key (:mod:`.resolve`).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass

from neurocur.results.names import condition_label
from neurocur.tables import deep_merge

from .resolved import ConditionTable, Entry, Resolved

__all__ = ["Plan", "expand", "grid", "world_layer"]


@dataclass(frozen=True)
class Plan:
    """One condition at one sweep point, as :mod:`.build` makes it.

    Parameters
    ----------
    label : str
        The condition's name at this point (``<condition>@<KEY>=<value>,...``; the name itself
        without a sweep): its results folder's.
    condition : ConditionTable
        The checked ``[conditions.NAME]`` table.
    point : dict
        The sweep point, a value by swept key; empty without a sweep.
    world : tuple of Entry
        The world tables, later ones winning (the files', the condition's, the point's, the
        command line's), each an :class:`~.resolved.Entry` whose key is the table's prefix.
    overrides : dict of str to Entry
        The ``"REGION.param"`` values of the files, the condition and the point, by key.
    set_params : dict of str to Entry
        The command line's ``"REGION.param"`` values, which win over ``overrides``.
    params : dict
        The winning value of each ``"REGION.param"`` key.
    """

    label: str
    condition: ConditionTable
    point: dict
    world: tuple[Entry, ...]
    overrides: dict[str, Entry]
    set_params: dict[str, Entry]
    params: dict

    @property
    def sweep(self) -> dict:
        """The sweep point, by the name a :class:`~.conditions.Condition` gives it (a label's collision
        names both points: :func:`~neurocur.results.names.condition_label`)."""
        return self.point


def expand(resolved: Resolved) -> list[Plan]:
    """Every condition of ``resolved`` at every point of its sweep, in order.

    Parameters
    ----------
    resolved : Resolved
        The experiment file, its ``extends`` chain and the command line's settings (:mod:`.resolve`).

    Returns
    -------
    list of Plan
        Condition by condition, each at every point of [`grid`][neurocur.experiments.expand.grid].

    Raises
    ------
    ConfigError
        For a condition name that is no folder name, or two points with one label
        ([`condition_label`][neurocur.results.names.condition_label]).
    """
    sweep = resolved.sweep
    world_sets = {}
    for key, entry in resolved.world_sets.items():  # world.sources.NAME.KEY nests
        world_sets = deep_merge(world_sets, world_layer({key: entry.value}))
    here = next((e.here for e in resolved.world_sets.values()), resolved.path.parent)
    set_world = Entry(world_sets, "--set", "world", here)
    plans: dict[str, Plan] = {}
    for table in resolved.conditions.values():
        for point in grid({k: e.value for k, e in sweep.items()}):
            swept_world = tuple(
                Entry(world_layer({k: v}), *((sweep[k].source, "sweep.world") if sweep[k].key else ("--set", "world")),
                      sweep[k].here)
                for k, v in point.items() if k.startswith("world."))
            point_params = {k: Entry(v, sweep[k].source, sweep[k].key, sweep[k].here)
                            for k, v in point.items() if not k.startswith("world.")}
            overrides = {**resolved.params, **table.params, **point_params}
            label = condition_label(table.name, point, table.source, plans)
            plans[label] = Plan(
                label=label,
                condition=table,
                point=point,
                world=(*resolved.world, table.world, *swept_world, set_world),
                overrides=overrides,
                set_params=dict(resolved.set_params),
                params={k: e.value for k, e in {**overrides, **resolved.set_params}.items()},
            )
    return list(plans.values())


def grid(sweep: Mapping[str, list]) -> list[dict]:
    """The points of the product of the swept values, in order (``[{}]`` without a sweep).

    Parameters
    ----------
    sweep : mapping of str to list
        Each swept key's values.

    Returns
    -------
    list of dict
        The points, the last key varying fastest.
    """
    keys = list(sweep)
    return [dict(zip(keys, values)) for values in itertools.product(*(sweep[k] for k in keys))]


def world_layer(point: Mapping) -> dict:
    """The ``world.*`` entries of a point as a (nested) world table.

    Parameters
    ----------
    point : mapping
        A sweep point (or any ``{dotted key: value}``); keys not starting with ``world.`` are left out.

    Returns
    -------
    dict
        ``{"world.sources.S.rows": 10}`` → ``{"sources": {"S": {"rows": 10}}}``.
    """
    layer: dict = {}
    for key, value in point.items():
        head, _, rest = key.partition(".")
        if head != "world":
            continue
        *tables, last = rest.split(".")
        node = layer
        for t in tables:
            node = node.setdefault(t, {})
        node[last] = value
    return layer
