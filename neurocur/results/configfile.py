"""A results folder's ``config.toml`` as the store reads and compares it.

:func:`read_config` reads it, every problem a one-line ConfigError naming the file and the
key (invalid or too deeply nested TOML, a key the store relies on with another type);
:func:`comparable` is what a resume compares.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path

from neurocur.config import ConfigError

__all__ = ["comparable", "folder_config", "lookup", "read_config"]

#: the resolved experiment's file in a results folder
CONFIG = "config.toml"

#: top-level keys compared on resume by their own rules (the code fingerprint), not as configuration
_NOT_COMPARED = ("code", "neurocur_version", "runs", "control")


def read_config(path: Path) -> dict:
    """The ``config.toml`` at ``path``, checked (:func:`check_config`).

    Parameters
    ----------
    path : path
        The ``config.toml`` file.

    Returns
    -------
    dict
        The resolved experiment.

    Raises
    ------
    ConfigError
        For invalid TOML or a key the store relies on with another type, naming the file and the key.
    """
    try:
        config = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError) as exc:
        raise ConfigError(path, None, "the resolved experiment neurocur wrote (valid TOML)",
                          f"{type(exc).__name__}: {str(exc) or 'nested too deep'}") from None
    return check_config(config, path)


def folder_config(root: Path) -> dict | None:
    """The ``config.toml`` of a results folder, checked ([`read_config`][neurocur.results.configfile.read_config]).

    Parameters
    ----------
    root : path
        The results folder (it need not exist).

    Returns
    -------
    dict or None
        The resolved experiment; None when the folder has no ``config.toml`` (yet).
    """
    path = Path(root) / CONFIG
    if not path.is_file():
        return None
    return read_config(path)


#: the keys of a config.toml whose type the store relies on, with the type expected
_CONFIG_TYPES = {"runs": (int, "a positive integer"), "steps": (int, "a positive integer"),
                 "seeds": (dict, "a table (entropy, spawn_key)"), "code": (list, "an array of code fingerprints"),
                 "conditions": (dict, "a table of condition tables")}


def check_config(config: dict, path: Path) -> dict:
    """``config`` (a folder's ``config.toml``) when the keys the store reads have their types, else a
    ConfigError naming ``path`` and the key."""
    for key, (kind, expected) in _CONFIG_TYPES.items():
        value = config.get(key)
        if key in config and (isinstance(value, bool) or not isinstance(value, kind)
                              or (kind is int and value < 1)):
            raise ConfigError(path, key, expected, f"{value!r}; use another --out folder")
    nested = [(f"code[{i}]", v) for i, v in enumerate(config.get("code", []))]
    nested += [(f"conditions.{k}", v) for k, v in config.get("conditions", {}).items()]
    for key, value in nested:
        if not isinstance(value, dict):
            raise ConfigError(path, key, "a table", f"{value!r}; use another --out folder")
    return config


def comparable(config: Mapping) -> dict:
    """``config`` as compared on resume: without the keys of :data:`_NOT_COMPARED`, descriptions, and
    the number of runs (a folder grows by runs; each run's seed depends only on its index).

    Parameters
    ----------
    config : mapping
        A resolved experiment (a ``config.toml`` as read, or the one an experiment would write).

    Returns
    -------
    dict
        The tree a resume compares.
    """
    kept = {k: v for k, v in config.items() if k not in _NOT_COMPARED}
    if isinstance(kept.get("seeds"), Mapping):
        kept["seeds"] = {k: v for k, v in kept["seeds"].items() if k not in ("spawn_key", "spawn_keys")}
    return _without_descriptions(kept)


def _without_descriptions(tree):
    """``tree`` without its ``description`` entries: prose, which does not change a result."""
    if isinstance(tree, dict):
        return {k: _without_descriptions(v) for k, v in tree.items() if k != "description"}
    return tree


def lookup(tree, path: tuple) -> str:
    """The value at ``path`` (from :func:`difference_path`) as text: its repr, ``"a table"``, or
    ``"nothing (not set)"`` when the tree has no such key.

    Parameters
    ----------
    tree : object
        A plain-data tree.
    path : tuple
        Keys and list indices into it.

    Returns
    -------
    str
        The value's text.
    """
    node = tree
    for part in path:
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            return "nothing (not set)"
    return "a table" if isinstance(node, dict) else repr(node)


