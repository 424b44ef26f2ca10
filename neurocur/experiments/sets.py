"""Command-line ``--set KEY=VALUE`` items: parsed as TOML literals and sorted by what they set.

``KEY`` is ``runs``, ``steps``, ``seed``, ``circuit``, ``name``, ``description``,
``world.KEY`` (nested tables by more dots: ``world.sources.NAME.KEY``) or ``REGION.param``; ``KEY=V1,V2`` sweeps the key
(:class:`Values`). :func:`neurocur.experiments.spec.load_experiment` applies them.
"""

from __future__ import annotations

import tomllib

from neurocur.config import ConfigError, describe
from neurocur.tables import deep_merge

from .sweep import world_layer

__all__ = ["Values", "parse_set", "classify_sets"]

SCALAR_KEYS = ("name", "description", "circuit", "runs", "steps", "seed")


class Values(list):
    """Several values of one ``--set KEY=V1,V2``: the key is swept over them."""


def parse_set(item: str) -> tuple[str, object]:
    """``"KEY=VALUE"`` → ``(KEY, value)``; VALUE is a TOML literal, else taken as a string.

    ``KEY=V1,V2,...`` (comma-separated values that are not one TOML literal) gives
    :class:`Values`, the values of a swept key.
    """
    key, eq, text = str(item).partition("=")
    key, text = key.strip(), text.strip()
    if not eq or not key:
        raise ConfigError(f"--set {item}", None, "KEY=VALUE (e.g. HPC.threshold=0.3)", describe(item))
    value = _literal(text)
    if isinstance(value, str) and "," in text:
        return key, Values(_literal(part.strip()) for part in text.split(","))
    return key, value


def _literal(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text
    except RecursionError:
        raise ConfigError("--set", None, "a TOML value", "arrays or tables nested too deeply to read") from None


def classify_sets(sets):
    top, world, params, sweep = {}, {}, {}, {}
    for item in sets:
        key, value = parse_set(item)
        head, _, rest = key.partition(".")
        if isinstance(value, Values):
            if head in SCALAR_KEYS or not rest or head in ("params", "conditions"):
                raise ConfigError(f"--set {key}", None, "several values only for a REGION.param or world.KEY",
                                  describe(list(value)))
            sweep[key] = list(value)
        elif head in SCALAR_KEYS:
            if rest:
                raise ConfigError(f"--set {key}", None, f"'{head}' without a sub-key", describe(key))
            top[head] = value
        elif head == "world":
            if not rest:
                raise ConfigError(f"--set {key}", None, "world.KEY (a parameter of the world type)", "'world'")
            world = deep_merge(world, world_layer({key: value}))  # world.sources.NAME.KEY nests
        elif head == "params" and rest:
            params[rest] = value
        elif rest and head not in ("conditions",):
            params[key] = value
        else:
            raise ConfigError(f"--set {key}", None,
                              "runs, steps, seed, circuit, name, description, world.KEY or REGION.param", describe(key))
    return top, world, params, sweep
