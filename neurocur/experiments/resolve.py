"""The entrance's first pass: an experiment file, its ``extends`` chain and the command line's
settings → one :class:`~.resolved.Resolved` table that remembers where each value came from.

Every file is read here, once: the experiment file and the files it extends
(:func:`neurocur.circuit.files.read_chain`, the reader circuit files use too), and each circuit
file a condition names (:func:`neurocur.circuit.files.read_circuit_file`). The next passes read
nothing: :mod:`.expand` takes conditions × sweep points, :mod:`.build` makes each one's circuit
and world parameters.

**Extends.** An experiment file may start from another, ``extends = "synthetic"`` (the name of
a shipped experiment, or a path relative to the file), and change only what differs: a
hypothesis run states its own conditions and inherits the chosen reading (world, parameters,
circuit, runs, steps, seed) of the experiment it extends, so the two cannot drift apart. Each
file's keys keep their file: relative paths resolve against the file that wrote them, and
errors name it. How the files combine:

- ``circuit``, ``runs``, ``steps``, ``seed``: the last file that gives one;
- ``[world]``: merged, later files winning key by key (nested tables merge, lists replace);
- ``[params]``: merged, later files winning per ``"REGION.param"``;
- ``[sweep]`` and ``[conditions]``: the last file's table as a whole (they are what an
  experiment is about, so they are not mixed across files);
- ``control`` (the condition the others are a test against, :mod:`.spec`) goes with
  ``[conditions]``: the file that gives the conditions, or a file extending it, names it; a
  file with conditions of its own has only the control it names;
- ``name`` and ``description``: the file's own only (default: the file's name).

**--set.** ``KEY=VALUE`` items (VALUE a TOML literal, else a string) win over the files and
over every condition: ``runs``, ``steps``, ``seed``, ``circuit``, ``name``, ``description``,
``world.KEY`` (nested tables by more dots: ``world.sources.NAME.KEY``) or ``REGION.param``;
``KEY=V1,V2`` sweeps the key (:class:`Values`): it replaces a swept key's values, a single
value restricts a swept key to it. ``--runs``, ``--steps`` and ``--seed`` win over both.

Every value is kept as an :class:`~.resolved.Entry`: the value, the file (or ``--set KEY``, ``--runs``)
that wrote it, its key there and the folder its relative paths start from; an error found by
a later pass names that file and key.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path

from neurocur.circuit.files import Layer, read_chain, read_circuit_file
from neurocur.config import ConfigError, describe
from neurocur.tables import check_keys, require, resolve_file, shipped_files

from .resolved import ConditionTable, Entry, Resolved

__all__ = ["Values", "parse_set", "resolve", "resolve_experiment", "shipped_experiments"]

TOP_KEYS = ("extends", "name", "description", "circuit", "runs", "steps", "seed", "world", "params", "sweep", "conditions",
            "control")
#: keys that describe one file and are not inherited from the file it extends
OWN_KEYS = ("name", "description")
SCALAR_KEYS = ("name", "description", "circuit", "runs", "steps", "seed")
CONDITION_KEYS = ("description", "circuit", "params", "world", "lesion", "replace", "edges", "fit")
#: a condition's tables that change its circuit as a file extending the circuit's would
VARIANT_KEYS = ("replace", "edges", "lesion")
DEFAULT_CONDITION = "default"


def resolve(path, *, sets: Sequence[str] = (), runs: int | None = None, steps: int | None = None,
            seed: int | None = None) -> Resolved:
    """Read the experiment file ``path`` (a path or a shipped experiment's name, e.g. ``"synthetic"``)
    and every file it extends, and apply ``--set`` items and ``--runs``/``--steps``/``--seed``.

    Parameters
    ----------
    path : path or str
        The experiment file, or a shipped experiment's name
        ([`resolve_experiment`][neurocur.experiments.resolve.resolve_experiment]).
    sets : sequence of str
        ``--set`` items, ``KEY=VALUE`` ([`parse_set`][neurocur.experiments.resolve.parse_set]).
    runs : int, optional
        ``--runs``: wins over the files and ``--set runs``.
    steps : int, optional
        ``--steps``: wins likewise.
    seed : int, optional
        ``--seed``: wins likewise.

    Returns
    -------
    Resolved
        The experiment's values, each with where it was written.

    Raises
    ------
    ConfigError
        For a key or value that fails its check, naming the file (or ``--set KEY``, ``--runs``) and the key.
    """
    path = resolve_experiment(path).resolve()
    layers = read_chain(path, "experiment", TOP_KEYS)
    cwd = Path.cwd()
    top_sets, world_sets, set_params, sweep_sets = _classify_sets(sets, cwd)

    swept = _last_with(layers, "sweep")
    sweep = {**(_sweep_table(swept.raw["sweep"], swept) if swept else {}), **sweep_sets}
    for sets_ in (set_params, world_sets):  # one value restricts a swept key
        for key in [k for k in sets_ if k in sweep]:
            sweep[key] = Entry([sets_.pop(key).value], f"--set {key}", None, cwd)

    scalars = {}
    for key in SCALAR_KEYS:
        if key in top_sets:
            scalars[key] = _check_scalar(key, top_sets[key], f"--set {key}", None, cwd)
        elif layer := _last_with(layers, key):
            scalars[key] = _check_scalar(key, layer.raw[key], layer.path, key, layer.here)
    for key, value in (("runs", runs), ("steps", steps), ("seed", seed)):
        if value is not None:
            scalars[key] = _check_scalar(key, value, f"--{key}", None, cwd)
    for key in ("runs", "steps"):
        if key not in scalars:
            raise ConfigError(path, key, "a positive integer", "nothing (the key is missing)")

    world = tuple(Entry(require(layer.raw, "world", dict, source=layer.path, expected="a table", default={}),
                        layer.path, "world", layer.here) for layer in layers)
    params = {}
    for layer in layers:
        table = require(layer.raw, "params", dict, source=layer.path, expected="a table", default={})
        params.update({k: Entry(v, layer.path, f"params.{k}", layer.here)
                       for k, v in _flatten_params(table, layer.path, "params").items()})

    conditions_layer = _last_with(layers, "conditions") or layers[-1]
    conditions = _conditions(conditions_layer, scalars.get("circuit"), "circuit" in top_sets, path)
    return Resolved(
        path=path,
        name=scalars.get("name", path.stem),
        description=scalars.get("description", ""),
        runs=scalars["runs"],
        steps=scalars["steps"],
        seed=scalars.get("seed"),
        world=world,
        world_sets=world_sets,
        params=params,
        set_params=set_params,
        sweep=sweep,
        conditions=conditions,
        circuits=_circuit_tables(dict.fromkeys(c.circuit for c in conditions.values())),
        control=_control(layers, conditions_layer, conditions),
    )


def _circuit_tables(paths) -> dict[Path, dict]:
    """The tables of each circuit file in ``paths``, every file (a shared base too) read once."""
    read: dict = {}
    return {path: read_circuit_file(path, read=read) for path in paths}


def _conditions(layer: Layer, circuit: Path | None, circuit_set: bool, path: Path) -> dict[str, ConditionTable]:
    """The ``[conditions]`` table of ``layer`` checked (``{"default": {}}`` without one); ``circuit``:
    the files' or the command line's circuit (``circuit_set``: the command line's, which wins)."""
    source, here = layer.path, layer.here
    raw = require(layer.raw, "conditions", dict, source=source, expected="a table of condition tables", default={})
    out = {}
    for name, table in (raw or {DEFAULT_CONDITION: {}}).items():
        prefix = f"conditions.{name}"
        if not isinstance(table, dict):
            raise ConfigError(source, prefix, "a table (circuit, params, world, description)", describe(table))
        check_keys(table, CONDITION_KEYS, source=source, prefix=prefix)
        if "circuit" in table and not circuit_set:
            own = _check_scalar("circuit", table["circuit"], source, f"{prefix}.circuit", here)
        elif circuit is not None:
            own = circuit
        else:
            raise ConfigError(path, "circuit", "a circuit file path (here or in every condition)", "nothing")
        world = require(table, "world", dict, source=source, prefix=prefix, expected="a table", default={})
        params = _flatten_params(require(table, "params", dict, source=source, prefix=prefix, expected="a table",
                                         default={}), source, f"{prefix}.params")
        description = require(table, "description", str, source=source, prefix=prefix, expected="a string", default="")
        fit = require(table, "fit", list, source=source, prefix=prefix, expected='a list of "REGION.param" keys',
                      default=[])
        if not all(isinstance(k, str) and "." in k for k in fit):
            raise ConfigError(source, f"{prefix}.fit", 'a list of "REGION.param" keys', describe(fit))
        out[name] = ConditionTable(
            name, description, own, {k: Entry(v, source, f"{prefix}.params.{k}", here) for k, v in params.items()},
            Entry(world, source, f"{prefix}.world", here), {k: table[k] for k in VARIANT_KEYS if k in table}, source,
            tuple(fit))
    return out


def _control(layers: list[Layer], conditions_layer: Layer, conditions: Mapping) -> str | None:
    """The ``control`` of the last file that names one, looking no further back than the file
    whose ``[conditions]`` these are; checked to name one of ``conditions``."""
    layer = next(layer for layer in reversed(layers) if layer is conditions_layer or "control" in layer.raw)
    control = require(layer.raw, "control", str, source=layer.path, default=None,
                      expected="the name of one of the conditions")
    if control is not None and control not in conditions:
        raise ConfigError(layer.path, "control", f"one of the conditions {', '.join(conditions)}", describe(control))
    return control


def _last_with(layers: list[Layer], key: str) -> Layer | None:
    """The last layer that gives ``key`` (the file's own for :data:`OWN_KEYS`), or None."""
    candidates = layers[-1:] if key in OWN_KEYS else layers
    return next((layer for layer in reversed(candidates) if key in layer.raw), None)


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


def _sweep_table(table, layer: Layer) -> dict[str, Entry]:
    """The ``[sweep]`` table checked: ``"REGION.param"`` or ``"world.KEY"`` keys, each a non-empty
    list of distinct values (the format: :mod:`.expand`)."""
    source = layer.path
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
        out[key] = Entry(list(values), source, where, layer.here)
    return out


# ---------------------------------------------------------------------------------------------- --set


class Values(list):
    """Several values of one ``--set KEY=V1,V2``: the key is swept over them."""


def parse_set(item: str) -> tuple[str, object]:
    """``"KEY=VALUE"`` → ``(KEY, value)``; VALUE is a TOML literal, else taken as a string.

    ``KEY=V1,V2,...`` (comma-separated values that are not one TOML literal) gives
    :class:`Values`, the values of a swept key.

    Parameters
    ----------
    item : str
        One ``--set`` item.

    Returns
    -------
    (str, object)
        The key (stripped) and its value.

    Raises
    ------
    ConfigError
        For an item without ``=`` or without a key.
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


def _classify_sets(sets, cwd: Path):
    """``--set`` items → (scalars, ``world.KEY`` entries, ``REGION.param`` entries, swept keys)."""
    top, world, params, sweep = {}, {}, {}, {}
    for item in sets:
        key, value = parse_set(item)
        head, _, rest = key.partition(".")
        entry = Entry(value, f"--set {key}", None, cwd)
        if isinstance(value, Values):
            if head in SCALAR_KEYS or not rest or head in ("params", "conditions"):
                raise ConfigError(f"--set {key}", None, "several values only for a REGION.param or world.KEY",
                                  describe(list(value)))
            sweep[key] = Entry(list(value), f"--set {key}", None, cwd)
        elif head in SCALAR_KEYS:
            if rest:
                raise ConfigError(f"--set {key}", None, f"'{head}' without a sub-key", describe(key))
            top[head] = value
        elif head == "world":
            if not rest:
                raise ConfigError(f"--set {key}", None, "world.KEY (a parameter of the world type)", "'world'")
            world[key] = Entry(value, "--set", key, cwd)
        elif head == "params" and rest:
            params[rest] = Entry(value, f"--set {rest}", None, cwd)
        elif rest and head not in ("conditions",):
            params[key] = entry
        else:
            raise ConfigError(f"--set {key}", None,
                              "runs, steps, seed, circuit, name, description, world.KEY or REGION.param", describe(key))
    return top, world, params, sweep


# ---------------------------------------------------------------------------------------------- names


def shipped_experiments() -> dict[str, Path]:
    """The experiment files shipped in the package (``neurocur/experiments_data/``), by name."""
    return shipped_files("experiment")


def resolve_experiment(value) -> Path:
    """The experiment file that ``value`` names: a path (relative to the working directory) when
    it is an existing path, ends with ``.toml`` or contains a path separator; otherwise the name
    of a shipped experiment. An unknown name is a ConfigError listing the shipped names.

    Parameters
    ----------
    value : path or str
        The ``EXPERIMENT`` argument: a path or a shipped experiment's name.

    Returns
    -------
    path
        The experiment file (a path as given, not resolved; a shipped experiment's file).

    Raises
    ------
    ConfigError
        For a name that is neither a path nor a shipped experiment's, listing the shipped names.
    """
    return resolve_file(value, Path(), "experiment", source=value, key=None)
