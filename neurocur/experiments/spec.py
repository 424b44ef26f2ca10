"""The experiment spec: a TOML file → validated conditions, each with its circuit built once.

An experiment file (a path, or the name of one shipped in ``neurocur/experiments_data/``,
e.g. ``"synthetic"``: :func:`resolve_experiment`) names a circuit, the world, the number of
runs and steps, the root seed, parameter overrides and, optionally, conditions::

    name = "synthetic"
    circuit = "cd_misfa"                      # a shipped circuit, or a path relative to this file
    runs = 25
    steps = 350000                            # frames per run
    seed = 2013
    control = "random_switching"              # optional: the conditions' control (see below)

    [world]                                   # neurocur.contexts.synthetic.SyntheticWorld
    contexts = ["S-A", "S-A", "S-B", "S-C", "S-D"]
    normalise = "global"
    # [world.sources]  S-X = "x.npy"          # user driving forces, (n_steps, n_dims)

    [params]                                  # "REGION.param" overrides of the circuit
    "HPC.threshold" = 0.3

    [conditions.curious]                      # a condition: overrides and/or a circuit variant
    [conditions.random_switching]
    circuit = "lesion_lc_random"
    params = { "LC.epsilon0" = 1.0 }          # merged over the top-level [params]
    # world = { normalise = "image" }         # merged over the top-level [world]
    # lesion = [{ region = "LC", how = "clamp", level = 8.0 }]   # lesions and drugs on the circuit
    # replace.LC = { type = "lc.softmax", params = { gain = 3.0 } }      # as a circuit file's [replace.LC]
    # edges = [{ from = "EC", signal = "slowness_progress", to = "VTA", input = "progress" }]  # its [[edges]]

The world table's keys are the parameters of its type (``world.type``, default
``"synthetic"``: :class:`~neurocur.contexts.synthetic.SyntheticParams`; ``"icub"``:
:class:`~neurocur.contexts.icub.ICubParams`; any type registered in
:data:`neurocur.contexts.WORLDS`). Paths in it are relative to the experiment file. A ``circuit`` value is a path when it is
an existing path, ends with ``.toml`` or contains a path separator, and otherwise the name
of a circuit shipped in ``neurocur/circuits/`` (:func:`neurocur.tables.resolve_file`).

A file may extend another, ``extends = "synthetic"``, and state only what differs
(:mod:`neurocur.experiments.files`: what is inherited, merged or replaced).

Without a ``[conditions]`` table there is one condition, ``default``. ``control`` names the
condition the others are a test against (e.g. random switching, section 4.3); it goes with the
``[conditions]`` table: a file that extends another inherits its control with its conditions (and
may name another of them), a file with conditions of its own has only the control it names. It is
recorded in ``config.toml``, where the analysis reads it (the efficiency figure of the first
condition against the control, :mod:`neurocur.analysis.figures.sets`). The first condition is the
reference of every comparison. Command-line
``--set KEY=VALUE`` settings (values are TOML literals; a bare word is a string) win
over the file and over every condition: ``runs``, ``steps``, ``seed``, ``circuit``,
``world.KEY`` or ``REGION.param``.

**Seeds (paired design).** Run *i* of every condition uses the same seed,
``SeedSequence(seed, spawn_key=(i,))`` (the *i*-th child of ``SeedSequence(seed).spawn``):
the world (mixing matrices, S-D, clock offsets) and every random draw of the circuit
start from the same state, so conditions are compared run by run. The seeds do not
depend on the number of runs, the conditions chosen or the number of worker processes.

Everything is validated here, once: each condition's circuit is loaded with its
overrides (the :class:`~neurocur.circuit.Circuit` is kept, so runs never parse it again)
and its world table is checked without building the world.

Configuration problems raise :class:`~neurocur.config.ConfigError` naming the file (or
``--set KEY``) and the key.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

import neurocur
from neurocur.circuit import Circuit
from neurocur.config import ConfigError, describe
from neurocur.contexts import WORLDS, World
from neurocur.results.names import condition_label
from neurocur.results.runinfo import seeds_record
from neurocur.tables import check_keys, require, resolve_file, shipped_files

from .conditions import Overrides, condition_world, lesioned, load_circuit
from .files import last_with, read_layers
from .sets import SCALAR_KEYS, classify_sets, parse_set
from .sweep import grid, sweep_table, world_layer

__all__ = ["Condition", "Experiment", "load_experiment", "parse_set", "resolve_experiment", "shipped_experiments"]

CONDITION_KEYS = ("description", "circuit", "params", "world", "lesion", "replace", "edges")
DEFAULT_CONDITION = "default"


@dataclass(frozen=True)
class Condition:
    """One condition: its circuit (loaded once, overrides applied), the circuit file, the
    ``"REGION.param"`` overrides and the world table."""

    name: str
    circuit_path: Path
    params: dict
    world: dict
    circuit: Circuit
    world_params: object = None
    description: str = ""
    #: the sweep point of this condition (``{"LC.gain": 0.5}``); empty without a sweep
    sweep: dict = field(default_factory=dict)

    @property
    def world_type(self) -> str:
        return self.world.get("type", "synthetic")

    @property
    def world_class(self) -> type[World]:
        return WORLDS.get(self.world_type)

    def make_world(self) -> World:
        return self.world_class.from_params(self.world_params)


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
    control: str | None = None

    def run_seed(self, run: int) -> np.random.SeedSequence:
        """The seed of run ``run`` (the same for every condition: paired comparison)."""
        if self.seed is None:
            raise ValueError("this experiment has no seed yet (give one in the file or with --set seed=N)")
        return np.random.SeedSequence(self.seed, spawn_key=(int(run),))

    def with_seed(self, seed: int) -> Experiment:
        return replace(self, seed=int(seed))

    def select(self, names: Sequence[str] | None = None) -> list[Condition]:
        """The named conditions (all when ``names`` is empty); a condition's name without a sweep
        point selects all its points; unknown names list the known ones."""
        if not names:
            return list(self.conditions.values())
        chosen = {}
        for n in names:
            found = [c for c in self.conditions.values() if n in (c.name, c.name.partition("@")[0])]
            if not found:
                known = dict.fromkeys(n.partition("@")[0] for n in self.conditions)
                raise ConfigError(f"--condition {n}", None, f"one of {', '.join(known)}", "an unknown condition")
            chosen.update((c.name, c) for c in found)
        return list(chosen.values())

    def resolved(self) -> dict:
        """The fully resolved experiment, as written to a results folder's ``config.toml``."""
        conditions = {}
        for cond in self.conditions.values():
            conditions[cond.name] = {
                "description": cond.description,
                "circuit": str(cond.circuit_path),
                "params": dict(cond.params),
                "world": dict(cond.world),
                **({"sweep": dict(cond.sweep)} if cond.sweep else {}),
                "resolved_circuit": cond.circuit.to_dict(),
            }
        return {
            "neurocur_version": neurocur.__version__,
            "experiment": str(self.path) if self.path else "",
            "name": self.name,
            "description": self.description,
            "runs": self.runs,
            "steps": self.steps,
            "seeds": seeds_record(self.seed),
            "conditions": conditions,
            **({"control": self.control} if self.control is not None else {}),
        }


def load_experiment(path, *, sets: Sequence[str] = (), runs: int | None = None, steps: int | None = None,
                    seed: int | None = None) -> Experiment:
    """Read and validate an experiment file (a path or a shipped experiment's name, e.g. ``"synthetic"``),
    applying ``--set`` items and ``--runs``/``--steps``/``--seed``."""
    path = resolve_experiment(path).resolve()
    layers = read_layers(path)
    cwd = Path.cwd()
    top_sets, world_sets, param_sets, sweep_sets = classify_sets(sets)
    swept = last_with(layers, "sweep")
    sweep = {**(sweep_table(swept.raw["sweep"], swept.path) if swept else {}), **sweep_sets}
    for key in [k for k in param_sets if k in sweep]:  # one value restricts a swept key
        sweep[key] = [param_sets.pop(key)]
    for key in [k for k in sweep if k.startswith("world.")]:
        found = _pop_dotted(world_sets, key.split(".")[1:])
        if found is not _ABSENT:
            sweep[key] = [found]

    scalars = {}
    for key in SCALAR_KEYS:
        if key in top_sets:
            scalars[key] = _check_scalar(key, top_sets[key], f"--set {key}", None, cwd)
        elif layer := last_with(layers, key):
            scalars[key] = _check_scalar(key, layer.raw[key], layer.path, key, layer.here)
    for key, value in (("runs", runs), ("steps", steps), ("seed", seed)):
        if value is not None:
            scalars[key] = _check_scalar(key, value, f"--{key}", None, cwd)
    for key in ("runs", "steps"):
        if key not in scalars:
            raise ConfigError(path, key, "a positive integer", "nothing (the key is missing)")

    base_world = [(require(layer.raw, "world", dict, source=layer.path, expected="a table", default={}),
                   layer.path, "world", layer.here) for layer in layers]
    base_params, param_origin = {}, {}
    for layer in layers:
        flat = _flatten_params(require(layer.raw, "params", dict, source=layer.path, expected="a table", default={}),
                               layer.path, "params")
        base_params.update(flat)
        param_origin.update(dict.fromkeys(flat, layer.path))

    conditions_layer = last_with(layers, "conditions") or layers[-1]
    source, here = conditions_layer.path, conditions_layer.here
    raw_conditions = require(conditions_layer.raw, "conditions", dict, source=source,
                             expected="a table of condition tables", default={})
    if not raw_conditions:
        raw_conditions = {DEFAULT_CONDITION: {}}
    control_layer = next(layer for layer in reversed(layers) if layer is conditions_layer or "control" in layer.raw)
    control = require(control_layer.raw, "control", str, source=control_layer.path, default=None,
                      expected="the name of one of the conditions")
    if control is not None and control not in raw_conditions:
        raise ConfigError(control_layer.path, "control", f"one of the conditions {', '.join(raw_conditions)}",
                          describe(control))
    conditions = {}
    for name, table in raw_conditions.items():
        prefix = f"conditions.{name}"
        if not isinstance(table, dict):
            raise ConfigError(source, prefix, "a table (circuit, params, world, description)", describe(table))
        check_keys(table, CONDITION_KEYS, source=source, prefix=prefix)
        if "circuit" in top_sets:
            circuit = scalars["circuit"]
        elif "circuit" in table:
            circuit = _check_scalar("circuit", table["circuit"], source, f"{prefix}.circuit", here)
        elif "circuit" in scalars:
            circuit = scalars["circuit"]
        else:
            raise ConfigError(path, "circuit", "a circuit file path (here or in every condition)", "nothing")
        cond_world = require(table, "world", dict, source=source, prefix=prefix, expected="a table", default={})
        cond_params = _flatten_params(
            require(table, "params", dict, source=source, prefix=prefix, expected="a table", default={}),
            source, f"{prefix}.params")
        description = require(table, "description", str, source=source, prefix=prefix, expected="a string", default="")
        for point in grid(sweep):
            point_params = {k: v for k, v in point.items() if not k.startswith("world.")}
            swept_world = (world_layer(point), *((swept.path, "sweep.world", swept.here) if swept
                                                 else ("--set", "world", cwd)))
            world, world_params = condition_world(
                [*base_world, (cond_world, source, f"{prefix}.world", here), swept_world,
                 (world_sets, "--set", "world", cwd)], path)
            overrides = Overrides(base_params, param_origin, {**cond_params, **point_params}, source, name)
            variant = {k: table[k] for k in ("replace", "edges") if k in table}
            built = lesioned(load_circuit(circuit, overrides, param_sets, variant), table.get("lesion", []), source,
                             f"{prefix}.lesion")
            params = {**base_params, **cond_params, **point_params, **param_sets}
            label = condition_label(name, point, source, conditions)
            conditions[label] = Condition(label, circuit, params, world, built, world_params, description, point)

    return Experiment(
        name=scalars.get("name", path.stem),
        path=path,
        description=scalars.get("description", ""),
        runs=scalars["runs"],
        steps=scalars["steps"],
        seed=scalars.get("seed"),
        conditions=conditions,
        control=control,
    )


_ABSENT = object()


def _pop_dotted(table: dict, parts: list[str]):
    """Remove and return ``table[p0][p1]...`` (``_ABSENT`` when there is none)."""
    node = table
    for part in parts[:-1]:
        node = node.get(part)
        if not isinstance(node, dict):
            return _ABSENT
    return node.pop(parts[-1], _ABSENT)


def _check_scalar(key, value, source, dotted, base_dir):
    kinds = {
        "name": (str, "a string"),
        "description": (str, "a string"),
        "circuit": (str, "a circuit file path or name (string)"),
        "runs": (int, "a positive integer"),
        "steps": (int, "a positive integer"),
        "seed": (int, "an integer >= 0"),
    }
    kind, expected = kinds[key]
    if isinstance(value, bool) or not isinstance(value, kind) or (kind is int and value < (0 if key == "seed" else 1)):
        raise ConfigError(source, dotted, expected, describe(value))
    if key == "circuit":
        resolved = resolve_file(value, base_dir, "circuit", source=source, key=dotted).resolve()
        if not resolved.is_file():
            raise ConfigError(source, dotted, "an existing circuit file", f"{value!r} (no such file: {resolved})")
        return resolved
    return value


def shipped_experiments() -> dict[str, Path]:
    """The experiment files shipped in the package (``neurocur/experiments_data/``), by name."""
    return shipped_files("experiment")


def resolve_experiment(value) -> Path:
    """The experiment file that ``value`` names: a path (relative to the working directory) when
    it is an existing path, ends with ``.toml`` or contains a path separator; otherwise the name
    of a shipped experiment. An unknown name is a ConfigError listing the shipped names."""
    return resolve_file(value, Path(), "experiment", source=value, key=None)


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
