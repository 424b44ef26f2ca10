"""World tables of experiment files: validation.

World types (``world.type``): ``"synthetic"`` (the default;
:class:`~neurocur.contexts.synthetic.SyntheticWorld`, keys ``contexts``, ``context_names``,
``sources``, ``visit_length``, ``normalise``, ``clock_offsets``, ``frame_shape``,
``learnable``, ``nonstationary``) and ``"icub"`` (:class:`~neurocur.contexts.icub.ICubWorld`,
keys ``n_episodes``, ``dataset_seed`` (the seed of the cached episode data set, not of the
runs), ``cache_dir`` (relative to the experiment file; default ``$NEUROCUR_CACHE/icub`` or
``~/.cache/neurocur/icub``), ``n_jobs`` (processes that simulate the data set) and the
tables ``scene`` (:class:`~neurocur.contexts.icub_scene.SceneParams` fields) and
``protocol`` (:class:`~neurocur.contexts.icub.EpisodeParams` fields)). A key of the other
type is an error. Validating an iCub experiment never simulates; the runner builds the
data set once, before its workers start.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from neurocur.config import ConfigError, describe
from neurocur.contexts import build_world
from neurocur.contexts.icub import EpisodeParams
from neurocur.contexts.icub_scene import SceneParams
from neurocur.contexts.sources import LEARNABLE, UNLEARNABLE
from neurocur.contexts.synthetic import NORMALISATIONS, PAPER_CONTEXTS
from neurocur.learn._validation import check_block, check_nonconstant

SYNTHETIC_KEYS = ("contexts", "context_names", "sources", "visit_length", "normalise", "clock_offsets",
                  "frame_shape", "learnable", "nonstationary")
ICUB_KEYS = ("n_episodes", "dataset_seed", "cache_dir", "n_jobs", "scene", "protocol")
WORLD_KEYS = ("type", *SYNTHETIC_KEYS, *ICUB_KEYS)
WORLD_TYPES = ("synthetic", "icub")
TYPE_KEYS = {"synthetic": SYNTHETIC_KEYS, "icub": ICUB_KEYS}
#: dataclass of each nested table of the iCub world table
ICUB_TABLES = {"scene": SceneParams, "protocol": EpisodeParams}


def check_world(table: Mapping, source, prefix: str, base_dir: Path, *, label_keys: bool = False) -> dict:
    """Check each world key on its own (types, ranges, source files); returns the table with absolute paths."""
    def err(key, expected, got):
        if label_keys:
            return ConfigError(f"--set {prefix}.{key}", None, expected, got)
        return ConfigError(source, f"{prefix}.{key}", expected, got)

    for key in table:
        if key not in WORLD_KEYS:
            raise err(key, f"one of the keys {list(WORLD_KEYS)}", "an unknown key")
    out = dict(table)

    def str_list(key, *, distinct=False):
        v = table[key]
        if not (isinstance(v, list) and v and all(isinstance(s, str) and s for s in v)):
            raise err(key, "a non-empty list of names (strings)", describe(v))
        if distinct and len(set(v)) != len(v):
            raise err(key, "distinct names", describe(v))

    if "type" in table and table["type"] not in WORLD_TYPES:
        raise err("type", f"one of {', '.join(map(repr, WORLD_TYPES))}", describe(table["type"]))
    for key in ("contexts", "learnable"):
        if key in table:
            str_list(key)
    if "context_names" in table:
        str_list("context_names", distinct=True)
    if "visit_length" in table:
        v = table["visit_length"]
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise err("visit_length", "a positive integer", describe(v))
    if "normalise" in table and table["normalise"] not in NORMALISATIONS:
        raise err("normalise", " or ".join(map(repr, NORMALISATIONS)), describe(table["normalise"]))
    if "clock_offsets" in table:
        v = table["clock_offsets"]
        ok = v in ("random", "zero") if isinstance(v, str) else (
            isinstance(v, list) and all(isinstance(o, int) and not isinstance(o, bool) and o >= 0 for o in v))
        if not ok:
            raise err("clock_offsets", "'random', 'zero' or a list of start steps (integers >= 0)", describe(v))
    if "frame_shape" in table:
        v = table["frame_shape"]
        if not (isinstance(v, list) and len(v) == 2 and all(isinstance(s, int) and not isinstance(s, bool) and s > 0
                                                             for s in v)):
            raise err("frame_shape", "[height, width] (two positive integers)", describe(v))
    for key, expected, low in (("n_episodes", "a positive integer", 1), ("n_jobs", "a positive integer", 1),
                               ("dataset_seed", "an integer >= 0", 0)):
        if key in table:
            v = table[key]
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise err(key, expected, describe(v))
    if "cache_dir" in table:
        v = table["cache_dir"]
        if not isinstance(v, str) or not v:
            raise err("cache_dir", "a folder path (string)", describe(v))
        out["cache_dir"] = str((base_dir / Path(v).expanduser()).resolve())
    for key, cls in ICUB_TABLES.items():
        if key in table:
            _check_dataclass_table(table[key], cls, lambda sub, expected, got, key=key: err(
                f"{key}.{sub}" if sub else key, expected, got))
    if "sources" in table:
        if not isinstance(table["sources"], dict):
            raise err("sources", "a table of source name = \".npy file path\"", describe(table["sources"]))
        out["sources"] = {}
        for name, file in table["sources"].items():
            if not isinstance(file, str):
                raise err(f"sources.{name}", "a .npy file path (string)", describe(file))
            resolved = (base_dir / file).resolve()
            _load_source(resolved, lambda expected, got, name=name: err(f"sources.{name}", expected, got))
            out["sources"][name] = str(resolved)
    return out


def _load_source(path: Path, err) -> np.ndarray:
    """Load one user source file; ``err(expected, got)`` builds the ConfigError."""
    if not path.is_file():
        raise err("an existing .npy file", f"{str(path)!r} (no such file)")
    try:
        arr = np.load(path, allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise err("a .npy file written by numpy.save", f"{str(path)!r} ({exc})") from None
    if arr.ndim != 2 or arr.shape[0] < 2:
        raise err("an array of shape (n_steps, n_dims) with rows as time", f"shape {arr.shape} in {path}")
    try:
        arr = check_block(arr, name=str(path), min_rows=2)
        check_nonconstant(arr, name=str(path))
    except ValueError as exc:
        raise err("a finite, non-constant array of shape (n_steps, n_dims)", str(exc)) from None
    return arr


def _check_dataclass_table(table, cls, err) -> None:
    """Check a table of ``cls`` fields (types from the defaults), then build ``cls`` once.

    ``err(sub_key, expected, got)`` builds the ConfigError (``sub_key`` None: the whole table).
    """
    if not isinstance(table, dict):
        raise err(None, f"a table of {cls.__name__} fields", describe(table))
    defaults = {f.name: f.default for f in dataclasses.fields(cls)}
    for key, value in table.items():
        if key not in defaults:
            raise err(key, f"one of the keys {list(defaults)}", "an unknown key")
        default = defaults[key]
        number = (int, float) if isinstance(default, float) else (int,)
        if isinstance(default, tuple):
            ok = (isinstance(value, list) and len(value) == len(default)
                  and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value))
            expected = f"a list of {len(default)} numbers"
        else:
            ok = isinstance(value, number) and not isinstance(value, bool)
            expected = "an integer" if number == (int,) else "a number"
        if not ok:
            raise err(key, expected, describe(value))
    try:
        _dataclass_from_table(cls, table)
    except ValueError as exc:
        raise err(None, f"consistent {cls.__name__} fields", f"an error: {exc}") from None


def _dataclass_from_table(cls, table: Mapping):
    """``cls(**table)`` with TOML lists turned into the tuples the dataclass holds."""
    return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in table.items()})


def merge_world(*layers: Mapping) -> dict:
    out: dict = {}
    for layer in layers:
        for key, value in layer.items():
            out[key] = {**out.get(key, {}), **value} if isinstance(value, dict) else value
    return out


def check_world_semantics(world: dict, source) -> None:
    """Checks across keys of the merged world table (a synthetic world is built once).

    The keys must belong to the world's type. An iCub world is not built here (that would
    simulate its data set): its nested tables are checked as merged.
    """
    kind = world.get("type", "synthetic")
    for key in world:
        if key != "type" and key not in TYPE_KEYS[kind]:
            raise ConfigError(source, f"world.{key}", f"a key of world type {kind!r} (one of {list(TYPE_KEYS[kind])})",
                              "a key of another world type")
    if kind == "icub":
        for key, cls in ICUB_TABLES.items():
            if key in world:
                _check_dataclass_table(world[key], cls, lambda sub, expected, got, key=key: ConfigError(
                    source, f"world.{key}.{sub}" if sub else f"world.{key}", expected, got))
        return
    sources = world.get("sources", {})
    contexts = world.get("contexts", list(PAPER_CONTEXTS))
    known = set(LEARNABLE) | set(UNLEARNABLE) | set(sources)
    for name in contexts:
        if name not in known:
            raise ConfigError(source, "world.contexts", f"source names among {', '.join(sorted(known))}",
                              f"{name!r} (add it under [world.sources])")
    for name in world.get("learnable", ()):
        if name not in contexts:
            raise ConfigError(source, "world.learnable", f"sources shown by a context ({', '.join(dict.fromkeys(contexts))})",
                              describe(name))
    try:
        build_world(world)
    except ValueError as exc:
        raise ConfigError(source, "world", "a consistent world table", f"an error: {exc}") from None
