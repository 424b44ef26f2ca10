"""Saving the state of live objects without pickle: a walker into JSON plus an ``.npz`` of arrays.

:func:`save_state` walks a dict of named *roots* (objects that exist again, freshly built,
when the state is loaded: a simulator's regions, world and recorder) and writes into a
folder:

* ``state.json``: ``{"format": FORMAT, "version": VERSION, "meta": {...}, "roots": {...}}``, each
  root's attributes encoded by the walker;
* ``arrays.npz``: every numpy array of a non-object dtype, by key.

Both are written and read by :mod:`.stateio`, which adds and checks their digests and the
arrays' declared dtypes and shapes, never follows a link and never unpickles.

What the walker takes, and nothing else (anything else is refused by its path and type):

* ``None``, ``bool``, ``int``, ``float``, ``str``, paths; numpy scalars (kept with their dtype);
* numpy arrays (object arrays element by element); ``numpy.random.Generator`` (its bit
  generator's name and state) and ``SeedSequence``;
* lists, tuples, sets, frozensets and dicts (any keys the walker takes), recursively;
* instances, enum members and classes of neurocur's own modules, or of the modules of a
  region or world plug-in that is loaded (:data:`~neurocur.results.fingerprint.PLUGIN_GROUPS`),
  through their ``__dict__`` and ``__slots__``.

An object, array or container reached twice is written once and referred to (``$ref``), so
shared state stays shared and cycles are fine; a root reached from another is referred to by
name (``$root``). :func:`load_state` restores each root's attributes in place, creating the
nested objects without calling their constructors; a class is looked up by module and name
only among the modules above (a state file never names code to run elsewhere). Every root's
attributes are decoded and checked first (a number where the freshly built root holds an
integer must be an integer, an array must keep the fresh one's dtype and dimensions, and the
caller's own checks), and only then set: a state that fails leaves the roots as they were.
"""

from __future__ import annotations

import enum
import importlib
import json
import pathlib
import sys
from collections.abc import Callable, Mapping
from importlib.metadata import entry_points
from pathlib import Path, PurePath

import numpy as np

from .fingerprint import PLUGIN_GROUPS
from .stateio import FORMAT, STATE, VERSION, StateError, read_state, write_state

__all__ = ["FORMAT", "VERSION", "StateError", "encode_state", "load_state", "save_state"]


def save_state(folder, roots: Mapping[str, object], meta: Mapping | None = None) -> Path:
    """Write the attributes of each root of ``roots`` (and ``meta``, plain JSON) into ``folder``,
    atomically (:func:`~.stateio.write_state`); returns ``folder``.

    Parameters
    ----------
    folder : path
        The state folder to write; an existing one is replaced.
    roots : mapping of str to object
        The objects whose attributes are saved, by name (what the walker takes: see above).
    meta : mapping, optional
        Plain JSON kept as ``state.json``'s ``meta``.

    Returns
    -------
    path
        ``folder``.

    Raises
    ------
    StateError
        For an object the walker does not take, naming its path and type.
    """
    return write_state(folder, *encode_state(roots, meta))


def encode_state(roots: Mapping[str, object], meta: Mapping | None = None) -> tuple[dict, dict[str, np.ndarray]]:
    """``(body, arrays)``: the state of ``roots`` as :func:`~.stateio.write_state` writes it (``state.json``'s
    content and the arrays by key), copied out of the live objects.

    Parameters
    ----------
    roots : mapping of str to object
        The objects whose attributes are encoded, by name.
    meta : mapping, optional
        Plain JSON kept as the body's ``meta``.

    Returns
    -------
    (dict, dict)
        ``state.json``'s content (without ``arrays`` and ``sha256``) and the arrays by key.

    Raises
    ------
    StateError
        For an object the walker does not take, naming its path and type.
    """
    encoder = _Encoder(roots)
    body = {"format": FORMAT, "version": VERSION, "meta": dict(meta or {}),
            "roots": {name: encoder.attributes(obj, name) for name, obj in roots.items()}}
    return json.loads(json.dumps(body)), {k: np.array(v) for k, v in encoder.arrays.items()}


#: ``check(meta, staged)``: the caller's checks of a state before it is set (``staged``: each root's
#: decoded attributes by name); raises StateError
Check = Callable[[dict, dict[str, dict]], None]


def load_state(folder, roots: Mapping[str, object], check: Check | None = None) -> dict:
    """Restore, in place, the attributes of each root of ``roots`` from ``folder`` (written by
    :func:`save_state` for roots of the same names) once the state has passed every check
    (:func:`~.stateio.read_state`'s, the roots' kinds, ``check``); returns the saved ``meta``.

    Parameters
    ----------
    folder : path
        The state folder.
    roots : mapping of str to object
        Freshly built objects of the same names as those saved; set only when every check passes.
    check : callable, optional
        ``check(meta, staged)``: the caller's checks before anything is set (``staged``: each root's
        decoded attributes by name); it raises StateError to refuse the state.

    Returns
    -------
    dict
        The saved ``meta``.

    Raises
    ------
    StateError
        When a check fails, naming the file and what did not match.
    """
    folder = Path(folder)
    body, arrays = read_state(folder)
    missing = set(body["roots"]) ^ set(roots)
    if missing:
        raise StateError(f"{folder / STATE}: key 'roots': expected the parts {sorted(roots)}, got "
                         f"{sorted(body['roots'])}")
    decoder = _Decoder(roots, arrays, folder)
    try:
        staged = {name: decoder.attributes(body["roots"][name]) for name in roots}
    except StateError:
        raise
    except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
        raise decoder.error(f"an entry it cannot decode ({type(exc).__name__}: {exc})") from None
    for name, attributes in staged.items():
        _check_kinds(folder, name, roots[name], attributes)
    if check is not None:
        check(body["meta"], staged)
    for name, obj in roots.items():
        decoder.fill(obj, staged[name])
    return body["meta"]


def _check_kinds(folder: Path, name: str, fresh, attributes: Mapping) -> None:
    """StateError when an attribute is not of the kind the freshly built root holds: an integer stays
    an integer, a number a number, an array an array of the same dtype and dimensions."""
    current = {**{s: getattr(fresh, s) for s in _slots(type(fresh)) if hasattr(fresh, s)},
               **getattr(fresh, "__dict__", {})}
    for key, value in attributes.items():
        if key not in current:
            continue
        now, expected = current[key], None
        if isinstance(now, np.ndarray):
            if not (isinstance(value, np.ndarray) and value.dtype == now.dtype and value.ndim == now.ndim):
                expected = f"an array of dtype {now.dtype} with {now.ndim} dimensions"
        elif isinstance(now, (bool, np.bool_)):
            if not isinstance(value, (bool, np.bool_)):
                expected = "a boolean"
        elif isinstance(now, (int, np.integer)):
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
                expected = "an integer"
        elif isinstance(now, (float, np.floating)):
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
                expected = "a number"
        if expected is not None:
            got = (f"an array of dtype {value.dtype} with {value.ndim} dimensions" if isinstance(value, np.ndarray)
                   else f"{value!r:.40} ({type(value).__name__})")
            raise StateError(f"{folder / STATE}: key 'roots.{name}.{key}': expected {expected}, as a freshly built "
                             f"{name} holds, got {got}")


def _allowed_modules() -> set[str]:
    """The modules of the region and world plug-ins loaded in this process."""
    found = set()
    for group in PLUGIN_GROUPS:
        for ep in entry_points(group=group):
            if ep.module in sys.modules:
                found.add(ep.module)
    return found


def _own(module: str, plugins: set[str]) -> bool:
    return module == "neurocur" or module.startswith("neurocur.") or module in plugins


class _Encoder:
    def __init__(self, roots: Mapping[str, object]):
        self.roots = {id(obj): name for name, obj in roots.items()}
        self.seen: dict[int, int] = {}
        self.keep: list = []  # what has an id in ``seen`` stays alive, so ids are not reused
        self.arrays: dict[str, np.ndarray] = {}
        self.plugins = _allowed_modules()

    def attributes(self, obj, path: str) -> dict:
        state = dict(getattr(obj, "__dict__", {}))
        for cls in type(obj).__mro__:
            for slot in getattr(cls, "__slots__", ()):
                if slot not in ("__dict__", "__weakref__") and hasattr(obj, slot):
                    state[slot] = getattr(obj, slot)
        return {key: self.encode(value, f"{path}.{key}") for key, value in state.items()}

    def encode(self, value, path: str):
        if isinstance(value, enum.Enum):
            return {"$enum": self._class_name(type(value), path), "name": value.name}
        if value is None or isinstance(value, (bool, str)):
            return value
        if type(value) is int:
            return value
        if type(value) is float:
            return value
        if isinstance(value, np.generic):
            if value.dtype.kind not in "biufcUS":
                raise StateError(f"cannot save {path}: a numpy scalar of dtype {value.dtype}")
            item = value.item()
            return {"$scalar": value.dtype.str, "value": [item.real, item.imag] if isinstance(item, complex) else item}
        if isinstance(value, type):
            return {"$class": self._class_name(value, path)}
        if isinstance(value, PurePath):
            return {"$path": str(value), "kind": type(value).__name__}
        key = id(value)
        if key in self.roots:
            return {"$root": self.roots[key]}
        if key in self.seen:
            return {"$ref": self.seen[key]}
        ref = self.seen[key] = len(self.seen)
        self.keep.append(value)
        if isinstance(value, np.ndarray):
            if value.dtype.hasobject:
                items = [self.encode(v, f"{path}[{i}]") for i, v in enumerate(value.ravel().tolist())]
                return {"$id": ref, "$objarray": list(value.shape), "items": items}
            if type(value) is not np.ndarray:
                raise StateError(f"cannot save {path}: a {type(value).__module__}.{type(value).__qualname__}")
            name = f"a{len(self.arrays)}"
            self.arrays[name] = value
            return {"$id": ref, "$array": name}
        if isinstance(value, np.random.Generator):
            bits = value.bit_generator
            return {"$id": ref, "$generator": type(bits).__name__, "state": self.encode(bits.state, f"{path}.state")}
        if isinstance(value, np.random.SeedSequence):
            return {"$id": ref, "$seedseq": self.encode({
                "entropy": value.entropy, "spawn_key": value.spawn_key, "pool_size": value.pool_size,
                "n_children_spawned": value.n_children_spawned}, path)}
        if type(value) in (list, tuple, set, frozenset):
            items = value if type(value) in (list, tuple) else sorted(value, key=repr)
            kind = {list: "$list", tuple: "$tuple", set: "$set", frozenset: "$frozenset"}[type(value)]
            return {"$id": ref, kind: [self.encode(v, f"{path}[{i}]") for i, v in enumerate(items)]}
        if type(value) is dict:
            return {"$id": ref, "$dict": [[self.encode(k, f"{path}.<key>"), self.encode(v, f"{path}[{k!r}]")]
                                          for k, v in value.items()]}
        cls = type(value)
        if _own(cls.__module__, self.plugins) and not callable(value):
            return {"$id": ref, "$object": self._class_name(cls, path), "state": self.attributes(value, path)}
        raise StateError(f"cannot save {path}: a {cls.__module__}.{cls.__qualname__} (the state walker takes "
                         "numbers, strings, arrays, generators, lists, dicts and neurocur's own objects)")

    def _class_name(self, cls: type, path: str) -> str:
        if not _own(cls.__module__, self.plugins) or "<locals>" in cls.__qualname__:
            raise StateError(f"cannot save {path}: the class {cls.__module__}.{cls.__qualname__} is not neurocur's "
                             "or a loaded plug-in's")
        return f"{cls.__module__}:{cls.__qualname__}"


class _Decoder:
    def __init__(self, roots: Mapping[str, object], arrays: Mapping[str, np.ndarray], folder: Path):
        self.roots = dict(roots)
        self.arrays = arrays
        self.folder = folder
        self.made: dict[int, object] = {}
        self.plugins = _allowed_modules()

    def attributes(self, encoded: Mapping) -> dict:
        """An object's attributes, decoded (not yet set)."""
        if not isinstance(encoded, Mapping):
            raise self.error(f"attributes that are not a JSON object ({str(encoded)[:40]})")
        return {key: self.decode(value) for key, value in encoded.items()}

    def fill(self, obj, attributes: Mapping) -> None:
        """Set ``obj``'s decoded ``attributes``."""
        for key, decoded in attributes.items():
            if hasattr(obj, "__dict__") and key not in _slots(type(obj)):
                obj.__dict__[key] = decoded
            else:
                object.__setattr__(obj, key, decoded)

    def decode(self, node):
        if not isinstance(node, (dict, list)):
            return node
        if isinstance(node, list):
            raise self.error(f"a plain JSON array {str(node)[:40]}")
        if "$root" in node:
            return self.roots[node["$root"]]
        if "$ref" in node:
            return self.made[node["$ref"]]
        if "$scalar" in node:
            value, dtype = node["value"], np.dtype(node["$scalar"])
            if dtype.kind not in "biufcUS":
                raise self.error(f"a numpy scalar of dtype {dtype}")
            return dtype.type(complex(*value) if isinstance(value, list) else value)
        if "$enum" in node:
            return self._class(node["$enum"])[node["name"]]
        if "$class" in node:
            return self._class(node["$class"])
        if "$path" in node:
            kind = getattr(pathlib, node.get("kind", ""), None)
            return (kind if isinstance(kind, type) and issubclass(kind, PurePath) else Path)(node["$path"])
        ref = node.get("$id")
        if "$array" in node:
            return self._keep(ref, np.array(self.arrays[node["$array"]]))
        if "$objarray" in node:
            items = [self.decode(v) for v in node["items"]]
            arr = np.empty(len(items), dtype=object)
            arr[:] = items
            return self._keep(ref, arr.reshape(node["$objarray"]))
        if "$generator" in node:
            bits = getattr(np.random, node["$generator"], None)
            if not (isinstance(bits, type) and issubclass(bits, np.random.BitGenerator)):
                raise self.error(f"an unknown bit generator {node['$generator']!r}")
            bit_generator = bits()
            bit_generator.state = self.decode(node["state"])
            return self._keep(ref, np.random.Generator(bit_generator))
        if "$seedseq" in node:
            return self._keep(ref, np.random.SeedSequence(**self.decode(node["$seedseq"])))
        if "$list" in node:
            out = self._keep(ref, [])
            out.extend(self.decode(v) for v in node["$list"])
            return out
        for kind, make in (("$tuple", tuple), ("$set", set), ("$frozenset", frozenset)):
            if kind in node:
                return self._keep(ref, make(self.decode(v) for v in node[kind]))
        if "$dict" in node:
            out = self._keep(ref, {})
            for k, v in node["$dict"]:
                out[self.decode(k)] = self.decode(v)
            return out
        if "$object" in node:
            cls = self._class(node["$object"])
            obj = self._keep(ref, cls.__new__(cls))
            self.fill(obj, self.attributes(node["state"]))
            return obj
        raise self.error(f"an entry it does not know ({sorted(node)[:3]})")

    def _keep(self, ref, value):
        self.made[ref] = value
        return value

    def _class(self, name: str) -> type:
        module, _, qualname = name.partition(":")
        if not _own(module, self.plugins):
            raise self.error(f"the class {name}, which is not neurocur's or a loaded plug-in's")
        try:
            obj = importlib.import_module(module)
            for part in qualname.split("."):
                obj = getattr(obj, part)
        except (ImportError, AttributeError):
            raise self.error(f"the class {name}, which this neurocur does not have") from None
        if not isinstance(obj, type):
            raise self.error(f"{name}, which is not a class")
        return obj

    def error(self, what: str) -> StateError:
        return StateError(f"{self.folder / STATE}: expected a state written by this neurocur, got {what}")


def _slots(cls: type) -> set[str]:
    return {s for c in cls.__mro__ for s in getattr(c, "__slots__", ())}
