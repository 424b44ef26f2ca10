"""Reading an experiment file: its layers, following ``extends``.

An experiment file may start from another, ``extends = "synthetic"`` (the name of a shipped
experiment, or a path relative to the file), and change only what differs: a hypothesis run
states its own conditions and inherits the chosen reading (world, parameters, circuit, runs,
steps, seed) of the experiment it extends, so the two cannot drift apart. Each file's keys
keep their file: relative paths resolve against the file that wrote them, and errors name it.

How the layers combine (:func:`neurocur.experiments.spec.load_experiment` applies this):

- ``circuit``, ``runs``, ``steps``, ``seed``: the last file that gives one;
- ``[world]``: merged, later files winning key by key (nested tables merge, lists replace);
- ``[params]``: merged, later files winning per ``"REGION.param"``;
- ``[sweep]`` and ``[conditions]``: the last file's table as a whole (they are what an
  experiment is about, so they are not mixed across files);
- ``name`` and ``description``: the file's own only (default: the file's name).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from neurocur.config import ConfigError
from neurocur.tables import check_keys, load_toml, require, resolve_file

__all__ = ["Layer", "OWN_KEYS", "last_with", "read_layers"]

TOP_KEYS = ("extends", "name", "description", "circuit", "runs", "steps", "seed", "world", "params", "sweep", "conditions",
            "control")
#: keys that describe one file and are not inherited from the file it extends
OWN_KEYS = ("name", "description")


@dataclass(frozen=True)
class Layer:
    """One experiment file of an ``extends`` chain: its parsed table and its path."""

    raw: dict
    path: Path

    @property
    def here(self) -> Path:
        """The folder that this file's relative paths start from."""
        return self.path.parent


def read_layers(path: Path, chain: tuple[Path, ...] = ()) -> list[Layer]:
    """The files of ``path``'s ``extends`` chain, the furthest base first and ``path`` last;
    each checked for unknown top-level keys."""
    path = path.resolve()
    raw = load_toml(path)
    check_keys(raw, TOP_KEYS, source=path)
    if "extends" not in raw:
        return [Layer(raw, path)]
    base = require(raw, "extends", str, source=path, expected="an experiment file path or name (string)")
    base_path = resolve_file(base, path.parent, "experiment", source=path, key="extends").resolve()
    if not base_path.is_file():
        raise ConfigError(path, "extends", "an existing experiment file", f"{base!r} (no such file: {base_path})")
    if base_path in (*chain, path):
        raise ConfigError(path, "extends", "a chain of experiment files without a loop",
                          " -> ".join(p.name for p in (*chain, path, base_path)))
    return [*read_layers(base_path, chain + (path,)), Layer(raw, path)]


def last_with(layers: list[Layer], key: str) -> Layer | None:
    """The last layer that gives ``key`` (the file's own for :data:`OWN_KEYS`), or None."""
    candidates = layers[-1:] if key in OWN_KEYS else layers
    return next((layer for layer in reversed(candidates) if key in layer.raw), None)
