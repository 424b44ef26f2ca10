"""Grid sweeps: a ``[sweep]`` table of parameter values → the points of their product.

An experiment file may sweep parameters of the circuit (``"REGION.param"``) and of the
world (``"world.KEY"``, or a nested ``"world.TABLE.KEY"``)::

    [sweep]
    "LC.gain" = [0.5, 1.0, 2.0]
    "world.normalise" = ["global", "image"]

Every condition is run at every point of the product (here 3 × 2 = 6 points), each as
its own condition named ``<condition>@<KEY>=<value>,<KEY>=<value>`` (keys sorted:
:func:`neurocur.results.names.condition_label`); run *i* of every
condition and point uses the same seed (paired). Each swept key is a column of every
results table. ``--set KEY=V1,V2`` replaces a key's values (a single value restricts the
sweep to it) or adds a swept key.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Mapping

from neurocur.config import ConfigError, describe

__all__ = ["grid", "sweep_table", "world_layer"]


def sweep_table(table, source) -> dict[str, list]:
    """The ``[sweep]`` table checked: ``"REGION.param"`` or ``"world.KEY"`` keys, each a non-empty
    list of distinct values."""
    if table is None:
        return {}
    if not isinstance(table, Mapping):
        raise ConfigError(source, "sweep", 'a table of "KEY" = [values]', describe(table))
    out = {}
    for key, values in table.items():
        where = f"sweep.{key}"
        if "." not in key or key.startswith(("params.", "conditions.")):
            raise ConfigError(source, where, 'a "REGION.param" or "world.KEY" key', describe(key))
        if not isinstance(values, list) or not values:
            raise ConfigError(source, where, "a non-empty list of values", describe(values))
        plain = [json.dumps(v, sort_keys=True) for v in values]
        if len(set(plain)) != len(plain):
            raise ConfigError(source, where, "distinct values", describe(values))
        out[key] = list(values)
    return out


def grid(sweep: Mapping[str, list]) -> list[dict]:
    """The points of the product of the swept values, in order (``[{}]`` without a sweep)."""
    keys = list(sweep)
    return [dict(zip(keys, values)) for values in itertools.product(*(sweep[k] for k in keys))]


def world_layer(point: Mapping) -> dict:
    """The ``world.*`` entries of a point as a (nested) world table."""
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
