"""Experiments: a TOML spec → conditions → seeded runs → tidy tables.

An experiment file (``experiments/*.toml``) names a circuit, the world, the number of
runs and steps, the root seed, parameter overrides and, optionally, conditions::

    name = "synthetic"
    circuit = "../circuits/cd_misfa.toml"     # relative to this file
    runs = 25
    steps = 350000                            # frames per run
    seed = 2013

    [world]                                   # neurocur.contexts.synthetic.SyntheticWorld
    contexts = ["S-A", "S-A", "S-B", "S-C", "S-D"]
    normalise = "global"
    # [world.sources]  S-X = "x.npy"          # user driving forces, (n_steps, n_dims)

    [params]                                  # "REGION.param" overrides of the circuit
    "HPC.threshold" = 0.3

    [conditions.curious]                      # a condition: overrides and/or a circuit variant
    [conditions.random_switching]
    circuit = "../circuits/lesion_lc_random.toml"
    params = { "LC.epsilon0" = 1.0 }          # merged over the top-level [params]
    # world = { normalise = "image" }         # merged over the top-level [world]

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

Without a ``[conditions]`` table there is one condition, ``default``. Command-line
``--set KEY=VALUE`` settings (values are TOML literals; a bare word is a string) win
over the file and over every condition: ``runs``, ``steps``, ``seed``, ``circuit``,
``world.KEY`` or ``REGION.param``.

**Seeds (paired design).** Run *i* of every condition uses the same seed,
``SeedSequence(seed, spawn_key=(i,))`` (the *i*-th child of ``SeedSequence(seed).spawn``):
the world (mixing matrices, S-D, clock offsets) and every random draw of the circuit
start from the same state, so conditions are compared run by run. The seeds do not
depend on the number of runs, the conditions chosen or the number of worker processes.

Configuration problems raise :class:`~neurocur.config.ConfigError` naming the file (or
``--set KEY``) and the key.
"""

from __future__ import annotations

import json
import math
import time
import tomllib
from collections.abc import Mapping, Sequence
import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

import neurocur
from neurocur.circuit import Circuit
from neurocur.config import ConfigError, check_keys, describe, load_toml, require
from neurocur.contexts.base import World
from neurocur.contexts.icub import EpisodeParams, ICubWorld
from neurocur.contexts.icub_scene import SceneParams
from neurocur.contexts.sources import LEARNABLE, SLOW_DIM, UNLEARNABLE
from neurocur.contexts.synthetic import NORMALISATIONS, PAPER_CONTEXTS, SyntheticWorld
from neurocur.learn._validation import check_block, check_nonconstant

__all__ = [
    "Condition",
    "Experiment",
    "RunResult",
    "load_experiment",
    "parse_set",
    "build_world",
    "prepare_world",
    "source_spec",
    "run_one",
    "module_quality",
    "icub_module_report",
    "dumps_toml",
    "first_difference",
]

TOP_KEYS = ("name", "description", "circuit", "runs", "steps", "seed", "world", "params", "conditions")
SCALAR_KEYS = ("name", "description", "circuit", "runs", "steps", "seed")
SYNTHETIC_KEYS = ("contexts", "context_names", "sources", "visit_length", "normalise", "clock_offsets",
                  "frame_shape", "learnable", "nonstationary")
ICUB_KEYS = ("n_episodes", "dataset_seed", "cache_dir", "n_jobs", "scene", "protocol")
WORLD_KEYS = ("type", *SYNTHETIC_KEYS, *ICUB_KEYS)
CONDITION_KEYS = ("description", "circuit", "params", "world")
WORLD_TYPES = ("synthetic", "icub")
TYPE_KEYS = {"synthetic": SYNTHETIC_KEYS, "icub": ICUB_KEYS}
#: dataclass of each nested table of the iCub world table
ICUB_TABLES = {"scene": SceneParams, "protocol": EpisodeParams}
#: reference episodes (pool indices, both contexts) whose slow-feature outputs each iCub run stores
ICUB_REFERENCE_EPISODES = (0, 1, 2)
DEFAULT_CONDITION = "default"


# ------------------------------------------------------------------------------ data


@dataclass(frozen=True)
class Condition:
    """One condition: a circuit file, ``"REGION.param"`` overrides and a world table."""

    name: str
    circuit: Path
    params: dict
    world: dict
    description: str = ""

    def load_circuit(self) -> Circuit:
        return Circuit.from_toml(self.circuit, overrides=self.params, overrides_source=f"condition {self.name!r}")

    @property
    def world_type(self) -> str:
        return self.world.get("type", "synthetic")

    def make_world(self) -> World:
        return build_world(self.world)


@dataclass(frozen=True)
class Experiment:
    """A loaded, validated experiment. ``seed`` is None when neither the file nor --set gave one."""

    name: str
    path: Path | None
    description: str
    runs: int
    steps: int
    seed: int | None
    conditions: dict[str, Condition]

    def run_seed(self, run: int) -> np.random.SeedSequence:
        """The seed of run ``run`` (the same for every condition: paired comparison)."""
        if self.seed is None:
            raise ValueError("this experiment has no seed yet (give one in the file or with --set seed=N)")
        return np.random.SeedSequence(self.seed, spawn_key=(int(run),))

    def select(self, names: Sequence[str] | None = None) -> list[Condition]:
        """The named conditions (all when ``names`` is empty); unknown names list the known ones."""
        if not names:
            return list(self.conditions.values())
        unknown = [n for n in names if n not in self.conditions]
        if unknown:
            raise ConfigError(f"--condition {unknown[0]}", None, f"one of {', '.join(self.conditions)}",
                              "an unknown condition")
        return [self.conditions[n] for n in dict.fromkeys(names)]

    def resolved(self) -> dict:
        """The fully resolved experiment, as written to a results folder's ``config.toml``."""
        conditions = {}
        for cond in self.conditions.values():
            conditions[cond.name] = {
                "description": cond.description,
                "circuit": str(cond.circuit),
                "params": dict(cond.params),
                "world": dict(cond.world),
                "resolved_circuit": cond.load_circuit().to_dict(),
            }
        return {
            "neurocur_version": neurocur.__version__,
            "experiment": str(self.path) if self.path else "",
            "name": self.name,
            "description": self.description,
            "runs": self.runs,
            "steps": self.steps,
            "seeds": {
                "entropy": self.seed,
                "spawn_keys": [list(self.run_seed(i).spawn_key) for i in range(self.runs)],
            },
            "conditions": conditions,
        }


# ------------------------------------------------------------------------------ loading


def parse_set(item: str) -> tuple[str, object]:
    """``"KEY=VALUE"`` → ``(KEY, value)``; VALUE is a TOML literal, else taken as a string."""
    key, eq, text = str(item).partition("=")
    key = key.strip()
    if not eq or not key:
        raise ConfigError(f"--set {item}", None, "KEY=VALUE (e.g. HPC.threshold=0.3)", describe(item))
    try:
        value = tomllib.loads(f"v = {text.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = text.strip()
    return key, value


def load_experiment(path, *, sets: Sequence[str] = (), runs: int | None = None, steps: int | None = None) -> Experiment:
    """Read and validate an experiment file, applying ``--set`` items and ``--runs``/``--steps``."""
    path = Path(path).resolve()
    raw = load_toml(path)
    check_keys(raw, TOP_KEYS, source=path)
    here, cwd = path.parent, Path.cwd()
    top_sets, world_sets, param_sets = _classify_sets(sets)

    scalars = {}
    for key in SCALAR_KEYS:
        if key in top_sets:
            scalars[key] = _check_scalar(key, top_sets[key], f"--set {key}", None, cwd)
        elif key in raw:
            scalars[key] = _check_scalar(key, raw[key], path, key, here)
    for key, value in (("runs", runs), ("steps", steps)):
        if value is not None:
            scalars[key] = _check_scalar(key, value, f"--{key}", None, cwd)
    for key in ("runs", "steps"):
        if key not in scalars:
            raise ConfigError(path, key, "a positive integer", "nothing (the key is missing)")

    base_world = _check_world(require(raw, "world", dict, source=path, expected="a table", default={}), path, "world", here)
    set_world = _check_world(world_sets, "--set", "world", cwd, label_keys=True)
    base_params = _flatten_params(require(raw, "params", dict, source=path, expected="a table", default={}), path, "params")

    raw_conditions = require(raw, "conditions", dict, source=path, expected="a table of condition tables", default={})
    if not raw_conditions:
        raw_conditions = {DEFAULT_CONDITION: {}}
    conditions = {}
    for name, table in raw_conditions.items():
        prefix = f"conditions.{name}"
        if not isinstance(table, dict):
            raise ConfigError(path, prefix, "a table (circuit, params, world, description)", describe(table))
        check_keys(table, CONDITION_KEYS, source=path, prefix=prefix)
        if "circuit" in top_sets:
            circuit = scalars["circuit"]
        elif "circuit" in table:
            circuit = _check_scalar("circuit", table["circuit"], path, f"{prefix}.circuit", here)
        elif "circuit" in scalars:
            circuit = scalars["circuit"]
        else:
            raise ConfigError(path, "circuit", "a circuit file path (here or in every condition)", "nothing")
        cond_world = _check_world(require(table, "world", dict, source=path, prefix=prefix, expected="a table",
                                          default={}), path, f"{prefix}.world", here)
        world = _merge_world(base_world, cond_world, set_world)
        _check_world_semantics(world, path)
        cond_params = _flatten_params(
            require(table, "params", dict, source=path, prefix=prefix, expected="a table", default={}),
            path, f"{prefix}.params")
        _check_circuit(circuit, base_params, cond_params, param_sets, path, name)
        params = {**base_params, **cond_params, **param_sets}
        description = require(table, "description", str, source=path, prefix=prefix, expected="a string", default="")
        conditions[name] = Condition(name, circuit, params, world, description)

    return Experiment(
        name=scalars.get("name", path.stem),
        path=path,
        description=scalars.get("description", ""),
        runs=scalars["runs"],
        steps=scalars["steps"],
        seed=scalars.get("seed"),
        conditions=conditions,
    )


def _classify_sets(sets):
    top, world, params = {}, {}, {}
    for item in sets:
        key, value = parse_set(item)
        head, _, rest = key.partition(".")
        if head in SCALAR_KEYS:
            if rest:
                raise ConfigError(f"--set {key}", None, f"'{head}' without a sub-key", describe(key))
            top[head] = value
        elif head == "world":
            if not rest:
                raise ConfigError(f"--set {key}", None, "world.KEY (one of " + ", ".join(WORLD_KEYS) + ")", "'world'")
            first, _, sub = rest.partition(".")
            if sub:  # world.sources.NAME
                world.setdefault(first, {})[sub] = value
            else:
                world[first] = value
        elif head == "params" and rest:
            params[rest] = value
        elif rest and head not in ("conditions",):
            params[key] = value
        else:
            raise ConfigError(f"--set {key}", None,
                              "runs, steps, seed, circuit, name, description, world.KEY or REGION.param", describe(key))
    return top, world, params


def _check_scalar(key, value, source, dotted, base_dir):
    kinds = {
        "name": (str, "a string"),
        "description": (str, "a string"),
        "circuit": (str, "a circuit file path (string)"),
        "runs": (int, "a positive integer"),
        "steps": (int, "a positive integer"),
        "seed": (int, "an integer >= 0"),
    }
    kind, expected = kinds[key]
    if isinstance(value, bool) or not isinstance(value, kind) or (kind is int and value < (0 if key == "seed" else 1)):
        raise ConfigError(source, dotted, expected, describe(value))
    if key == "circuit":
        resolved = (base_dir / value).resolve()
        if not resolved.is_file():
            raise ConfigError(source, dotted, "an existing circuit file", f"{value!r} (no such file: {resolved})")
        return resolved
    return value


def _flatten_params(table: Mapping, source, prefix: str) -> dict:
    """``{"HPC.threshold": 0.3}`` or ``{"HPC": {"threshold": 0.3}}`` → flat ``"REGION.param"`` keys."""
    flat = {}
    for key, value in table.items():
        if isinstance(value, dict):
            for sub, v in value.items():
                if isinstance(v, dict):
                    raise ConfigError(source, f"{prefix}.{key}.{sub}", "a parameter value", describe(v))
                flat[f"{key}.{sub}"] = v
        elif "." not in key:
            raise ConfigError(source, f"{prefix}.{key}", "a 'REGION.param' key (e.g. \"HPC.threshold\")", "no dot")
        else:
            flat[key] = value
    return flat


def _check_world(table: Mapping, source, prefix: str, base_dir: Path, *, label_keys: bool = False) -> dict:
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


def _merge_world(*layers: Mapping) -> dict:
    out: dict = {}
    for layer in layers:
        for key, value in layer.items():
            out[key] = {**out.get(key, {}), **value} if isinstance(value, dict) else value
    return out


def _check_world_semantics(world: dict, source) -> None:
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


def _check_circuit(circuit: Path, base_params: dict, cond_params: dict, set_params: dict, source, condition: str):
    """Load the circuit once with the overrides so that errors surface before any run starts."""
    try:
        loaded = Circuit.from_toml(circuit, overrides={**base_params, **cond_params}, overrides_source=source)
    except ConfigError as exc:
        if exc.source == str(source) and exc.key is not None:
            where = f"conditions.{condition}.params" if exc.key in cond_params else "params"
            raise ConfigError(source, f"{where}.{exc.key}", exc.expected, exc.got) from None
        raise
    try:
        loaded.with_params(set_params, source="--set")
    except ConfigError as exc:
        raise ConfigError(f"--set {exc.key}", None, exc.expected, exc.got) from None


# ------------------------------------------------------------------------------ worlds


def build_world(world: Mapping) -> World:
    """A world from a validated world table (source files and cache folder as absolute paths).

    An iCub world simulates its episode data set on first use and reads the cache after.
    """
    if world.get("type", "synthetic") == "icub":
        return ICubWorld(
            n_episodes=world.get("n_episodes", 70), seed=world.get("dataset_seed", 0),
            cache_dir=world.get("cache_dir"), n_jobs=world.get("n_jobs", 2),
            scene=_dataclass_from_table(SceneParams, world.get("scene", {})),
            protocol=_dataclass_from_table(EpisodeParams, world.get("protocol", {})),
        )
    kwargs = {k: world[k] for k in ("contexts", "context_names", "visit_length", "normalise", "frame_shape",
                                    "nonstationary") if k in world}
    if "clock_offsets" in world:
        kwargs["clock_offsets"] = world["clock_offsets"]
    sources = {name: np.load(file, allow_pickle=False) for name, file in world.get("sources", {}).items()}
    return SyntheticWorld(sources=sources, **kwargs)


def prepare_world(world: Mapping) -> None:
    """Make a world table cheap to build in every run: simulate an iCub data set into its cache.

    Called by the runner once, before its worker processes start (so they never simulate
    the same data set side by side). Nothing to do for a synthetic world.
    """
    if world.get("type", "synthetic") == "icub":
        build_world(world)


def source_spec(condition: Condition, world: World | None = None):
    """The :class:`neurocur.analysis.stats.SourceSpec` of a condition's world.

    Synthetic world. Learnable sources: ``world.learnable`` if given, else the built-in
    learnable sources shown (S-A, S-B, S-C, in Ω order) followed by the user sources in
    context order.

    iCub world: the contexts ``topple`` and ``roll``, each its own source, both learnable,
    in Ω order (topple easier; docs/icub.md). The world is not built.
    """
    from neurocur.analysis.stats import SourceSpec

    if condition.world_type == "icub":
        from neurocur.analysis.icub import ICUB

        return ICUB
    world = world or condition.make_world()
    shown = list(dict.fromkeys(world.source_names))
    default = [s for s in LEARNABLE if s in shown] + [s for s in shown if s in condition.world.get("sources", {})
                                                      and s not in LEARNABLE]
    learnable = condition.world.get("learnable", default)
    return SourceSpec(tuple(world.context_names), tuple(world.source_names), tuple(learnable))


# ------------------------------------------------------------------------------ one run


@dataclass(frozen=True)
class RunResult:
    """The tables and summary of one run (written as episodes.parquet, modules.parquet, run.json)."""

    condition: str
    run: int
    episodes: pd.DataFrame
    modules: pd.DataFrame
    summary: dict
    #: further per-run tables of the world type, written as ``<name>.parquet`` (iCub: ``features``)
    tables: Mapping[str, pd.DataFrame] = dataclasses.field(default_factory=dict)


def _abs_corr(a: np.ndarray, b: np.ndarray) -> float:
    """|Pearson correlation| of two series; NaN when either is constant."""
    if np.std(a) == 0.0 or np.std(b) == 0.0:
        return math.nan
    return float(abs(np.corrcoef(a, b)[0, 1]))


def module_quality(module, frames: np.ndarray, source: np.ndarray) -> float:
    """|corr| of a module's slowest output on ``frames`` with the source's slow dimension (NaN if flat)."""
    return _abs_corr(module.transform(frames)[:, 0], source[:, SLOW_DIM])


def _synthetic_module_report(world: SyntheticWorld, library, modules: pd.DataFrame):
    """Per stored module: its source and :func:`module_quality` on its context's frames."""
    sources, quality = [], []
    for row in modules.itertuples(index=False):
        source = world.source_of(int(row.context))
        sources.append(source)
        quality.append(module_quality(library[int(row.module)], world.context_frames(int(row.context)),
                                      world.source_signal(source)))
    return sources, quality, {}, {}


def icub_module_report(world: ICubWorld, library, modules: pd.DataFrame):
    """What each stored module's slowest output y₀ encodes, over every cached episode.

    Returns ``(sources, quality, columns, tables)``. Per module (a row of ``modules``,
    learned in context ``c``), all on the pooled frames of every episode of a context:

    - ``quality``: |corr(y₀, displacement)| on context ``c`` (the object's distance from
      its start, ``world.displacement``: "object displaced or not", section 4.2.2);
    - ``arm_corr``: |corr(y₀, arm joint state)| on context ``c`` (invariance to the arm);
    - ``other_quality``: |corr(y₀, displacement)| on the other context;
    - ``context_corr``: |corr(y₀, context index)| on both contexts (section 4.2.1: a module
      learned across both contexts codes for the context).

    ``tables["features"]``: every module's outputs on the reference episodes
    ``ICUB_REFERENCE_EPISODES`` of both contexts, one row per (module, frame): module,
    context, episode_index, frame, state, displacement, contact_frame, y0, y1, ...
    """
    n_modules = len(modules)
    J = library[0].n_components if library else 0
    columns = ["module", "context", "episode_index", "frame", "state", "displacement", "contact_frame",
               *(f"y{j}" for j in range(J))]
    extra = {"arm_corr": [], "other_quality": [], "context_corr": []}
    if not library:
        return [], [], extra, {"features": pd.DataFrame(columns=columns)}
    proj = np.concatenate([m.projection_ for m in library], axis=1)
    offset = np.concatenate([m.mean_ @ m.projection_ for m in library])
    outputs, displacement, states, contexts, reference = [], [], [], [], []
    for c in range(world.n_contexts):
        for i in range(world.n_episodes):
            ep = world.episode(c, i)
            y = (ep.frames @ proj - offset).reshape(len(ep.frames), n_modules, J)
            d = world.displacement(c, i)
            outputs.append(y)
            displacement.append(d)
            states.append(ep.states)
            contexts.append(np.full(len(d), c))
            if i in ICUB_REFERENCE_EPISODES:
                frame = np.arange(len(d))
                for m in range(n_modules):
                    reference.append(pd.DataFrame({
                        "module": m, "context": c, "episode_index": i, "frame": frame, "state": ep.states,
                        "displacement": d, "contact_frame": world.contact_frame(c, i),
                        **{f"y{j}": y[:, m, j] for j in range(J)}}))
    features = pd.concat(reference, ignore_index=True)[columns]
    context_of = np.concatenate(contexts)
    y0 = np.concatenate(outputs)[:, :, 0]
    displacement, states = np.concatenate(displacement), np.concatenate(states)
    sources, quality = [], []
    for row in modules.itertuples(index=False):
        m, c = int(row.module), int(row.context)
        own, other = context_of == c, context_of != c
        sources.append(world.source_names[c])
        quality.append(_abs_corr(y0[own, m], displacement[own]))
        extra["arm_corr"].append(_abs_corr(y0[own, m], states[own]))
        extra["other_quality"].append(_abs_corr(y0[other, m], displacement[other]))
        extra["context_corr"].append(_abs_corr(y0[:, m], context_of.astype(np.float64)))
    return sources, quality, extra, {"features": features}


def _gates(episodes: pd.DataFrame, modules: pd.DataFrame, names: Sequence[str]) -> list[str]:
    out = []
    for row in modules.itertuples(index=False):
        later = episodes[(episodes["episode"] > row.episode) & (episodes["gating_module"] == row.module)]
        out.append(",".join(names[c] for c in sorted(later["context"].unique())))
    return out


def run_one(condition: Condition, run: int, steps: int, seed: np.random.SeedSequence, *, progress=None) -> RunResult:
    """Simulate one run of ``condition`` for ``steps`` frames from ``seed``.

    Adds ``run`` and ``condition`` in front of the simulator's episodes and modules
    tables, and per module ``source`` (the source of the context it was learned in),
    ``quality`` (synthetic: :func:`module_quality` on that context's frames; iCub: see
    :func:`icub_module_report`, which also adds columns and the ``features`` table) and
    ``gates`` (the names of the contexts whose episodes it gated after it was stored,
    comma-separated).
    """
    started = time.perf_counter()
    world = condition.make_world()
    sim = condition.load_circuit().build(world, seed=seed)
    sim.run(steps, progress=progress)
    episodes = sim.episodes()
    modules = sim.modules()
    library = sim.regions["EC"].library
    names = world.context_names
    report = icub_module_report if condition.world_type == "icub" else _synthetic_module_report
    sources, quality, columns, tables = report(world, library, modules)
    modules = modules.assign(source=pd.Series(sources, dtype=object, index=modules.index),
                             quality=pd.Series(quality, dtype=np.float64, index=modules.index),
                             gates=pd.Series(_gates(episodes, modules, names), dtype=object, index=modules.index),
                             **{k: pd.Series(v, dtype=np.float64, index=modules.index) for k, v in columns.items()})
    for table in (episodes, modules, *tables.values()):
        table.insert(0, "condition", condition.name)
        table.insert(1, "run", int(run))
    summary = {
        "condition": condition.name,
        "run": int(run),
        "seed": {"entropy": seed.entropy, "spawn_key": list(seed.spawn_key)},
        "steps": int(steps),
        "frames": int(episodes["n_frames"].sum()),
        "n_episodes": len(episodes),
        "n_modules": len(modules),
        "order": sources,
        "module_steps": [int(s) for s in modules["step"]],
        "quality": [None if math.isnan(q) else q for q in quality],
        "contexts": [{"name": n, "source": s} for n, s in zip(names, world.source_names)],
        "learnable": list(source_spec(condition, world).learnable),
        "seconds": round(time.perf_counter() - started, 3),
    }
    return RunResult(condition.name, int(run), episodes, modules, summary, tables)


# ------------------------------------------------------------------------------ TOML out


def dumps_toml(data: Mapping, *, header: str = "") -> str:
    """A small TOML writer for plain data (str, int, float, bool, lists, nested tables).

    Tables nested in lists are written as inline tables. ``tomllib.loads`` of the result
    equals ``data`` (tuples and Paths come back as lists and strings).
    """
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    _write_table(lines, data, ())
    return "\n".join(lines).strip("\n") + "\n"


def _write_table(lines, table: Mapping, path: tuple):
    scalars = {k: v for k, v in table.items() if not isinstance(v, Mapping)}
    tables = {k: v for k, v in table.items() if isinstance(v, Mapping)}
    if path and (scalars or not tables):
        lines.append("")
        lines.append("[" + ".".join(_key(p) for p in path) + "]")
    for key, value in scalars.items():
        lines.append(f"{_key(key)} = {_value(value)}")
    for key, value in tables.items():
        _write_table(lines, value, path + (key,))


def _key(key) -> str:
    key = str(key)
    if key and all(c.isalnum() or c in "-_" for c in key) and key.isascii():
        return key
    return json.dumps(key)


def _value(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(value, (str, Path)):
        return json.dumps(str(value), ensure_ascii=False)
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML: {value!r}")


def first_difference(old, new, prefix: str = "") -> str | None:
    """The first dotted key at which two plain-data trees differ (None when equal)."""
    if isinstance(old, Mapping) and isinstance(new, Mapping):
        for key in list(dict.fromkeys([*old, *new])):
            where = f"{prefix}.{key}" if prefix else str(key)
            if key not in old or key not in new:
                return where
            found = first_difference(old[key], new[key], where)
            if found:
                return found
        return None
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        for i, (a, b) in enumerate(zip(old, new)):
            found = first_difference(a, b, f"{prefix}[{i}]")
            if found:
                return found
        return None
    same = old == new or (isinstance(old, float) and isinstance(new, float) and math.isnan(old) and math.isnan(new))
    return None if same else (prefix or "(root)")
