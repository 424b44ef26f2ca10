"""Reading configuration files: TOML files and the tables in them.

Circuit files (``neurocur/circuits/*.toml``) and experiment files (``neurocur/experiments_data/*.toml``) are read
with :func:`load_toml` and their tables checked with :func:`check_keys` and
:func:`require`; every problem is a :class:`~neurocur.config.ConfigError` naming the file
and the key. The parameters inside the tables are checked by their declared specs
(:mod:`neurocur.config`). Loading a file never executes code.

The circuits and experiments shipped in the package (``neurocur/circuits/``,
``neurocur/experiments_data/``) are named without path: :func:`resolve_file` tells a name
from a path, and :func:`shipped_files` finds them with :mod:`importlib.resources`, so they
are found from an installed wheel too.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import importlib.resources
import os
import stat
import tomllib
from collections.abc import Mapping
from pathlib import Path

from .config import ConfigError, describe, join_key

__all__ = ["check_keys", "deep_merge", "load_toml", "require", "resolve_file", "shipped_files"]


def load_toml(path) -> dict:
    """Read a TOML file into a dict; a missing, unreadable or binary file, a directory, a FIFO or
    other file that is not a regular file (never opened for reading: it could block), a syntax
    error or tables nested too deeply for the parser is a ConfigError.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    dict
        Its tables and values.
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise ConfigError(path, None, "an existing TOML file", "no such file") from None
    except OSError as exc:
        raise ConfigError(path, None, "a readable TOML file", f"{exc.strerror or exc}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        if stat.S_ISDIR(mode):
            raise ConfigError(path, None, "a TOML file", "a directory")
        raise ConfigError(path, None, "a TOML file (a regular file)", "a FIFO, socket or device")
    os.set_blocking(fd, True)
    with open(fd, "rb") as fh:
        try:
            return tomllib.load(fh)
        except OSError as exc:
            raise ConfigError(path, None, "a readable TOML file", f"{exc.strerror or exc}") from None
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(path, None, "valid TOML", f"a syntax error ({exc})") from None
        except UnicodeDecodeError:
            raise ConfigError(path, None, "a TOML file (UTF-8 text)", "a binary file") from None
        except RecursionError:
            raise ConfigError(path, None, "valid TOML", "arrays or tables nested too deeply to read") from None


def check_keys(table: Mapping, allowed, *, source, prefix: str = "", required=()) -> None:
    """Raise ConfigError for a key of ``table`` outside ``allowed`` or a missing required key.

    Parameters
    ----------
    table : mapping
        A TOML table.
    allowed : collection of str
        The keys it may have.
    source : str
        The file named in the message.
    prefix : str
        The table's dotted path, prefixed to a key in the message.
    required : collection of str
        The keys it must have.
    """
    for key in required:
        if key not in table:
            raise ConfigError(source, join_key(prefix, key), "this key to be present", "nothing")
    allowed = tuple(allowed)
    for key in table:
        if key not in allowed:
            raise ConfigError(source, join_key(prefix, key), f"one of the keys {list(allowed)}", "an unknown key")


_MISSING = object()


def require(table: Mapping, key: str, types, *, source, prefix: str = "", expected: str, default=_MISSING):
    """Return ``table[key]`` checked against ``types`` (bool never passes for int/float).

    Parameters
    ----------
    table : mapping
        A TOML table.
    key : str
        The key read.
    types : type or tuple of type
        The types its value may have.
    source : str
        The file named in a message.
    prefix : str
        The table's dotted path, prefixed to the key in a message.
    expected : str
        What a message says was expected.
    default : optional
        The value when the key is absent (without one, an absent key is a ConfigError).

    Returns
    -------
    object
        The checked value.
    """
    if key not in table:
        if default is not _MISSING:
            return default
        raise ConfigError(source, join_key(prefix, key), expected, "nothing (the key is missing)")
    value = table[key]
    types = types if isinstance(types, tuple) else (types,)
    if (isinstance(value, bool) and bool not in types) or not isinstance(value, types):
        raise ConfigError(source, join_key(prefix, key), expected, describe(value))
    return value


def deep_merge(base: Mapping, override: Mapping) -> dict:
    """A new dict: ``override`` merged into ``base``; nested tables merge, other values replace.

    Parameters
    ----------
    base : mapping
        The table merged into.
    override : mapping
        The table whose values win.

    Returns
    -------
    dict
        The merged table (neither argument is changed).
    """
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = value
    return out


#: kind -> folder of the package that holds the shipped TOML files of that kind
SHIPPED = {"circuit": "circuits", "experiment": "experiments_data", "invariance": "experiments_data"}
#: the top-level key that tells an invariance demonstration (``neurocur invariance``) from an experiment
#: (``neurocur run``) among the files of ``experiments_data/``
INVARIANCE_KEY = "source"
_extracted = contextlib.ExitStack()
atexit.register(_extracted.close)


def shipped_files(kind: str) -> dict[str, Path]:
    """The TOML files of ``kind`` (``"circuit"``, ``"experiment"`` or ``"invariance"``) shipped in the
    package, by name. Experiments and invariance demonstrations share ``experiments_data/``; a file
    with a top-level :data:`INVARIANCE_KEY` is an invariance demonstration.

    Parameters
    ----------
    kind : str
        ``"circuit"``, ``"experiment"`` or ``"invariance"``.

    Returns
    -------
    dict of str to Path
        The files by name.
    """
    folder = importlib.resources.files("neurocur").joinpath(SHIPPED[kind])
    if not folder.is_dir():
        return {}
    found = {}
    for item in sorted(folder.iterdir(), key=lambda t: t.name):
        if item.name.endswith(".toml") and item.is_file():
            path = item if isinstance(item, Path) else _extracted.enter_context(importlib.resources.as_file(item))
            if kind == "circuit" or _shipped_kind(Path(path)) == kind:
                found[item.name[: -len(".toml")]] = Path(path)
    return found


@functools.cache
def _shipped_kind(path: Path) -> str:
    return "invariance" if INVARIANCE_KEY in load_toml(path) else "experiment"


def resolve_file(value, base_dir: Path, kind: str, *, source, key) -> Path:
    """The file that ``value`` names: a path (relative to ``base_dir``) when it is an existing
    path, ends with ``.toml`` or contains a path separator (returned as ``base_dir / value``,
    not resolved); otherwise the name of a shipped file of ``kind``. A directory never shadows a
    shipped name (``--out icub`` leaves ``icub`` the shipped experiment). An unknown name is a
    ConfigError (``source``, ``key``) listing the names.

    Parameters
    ----------
    value : str
        A path or a shipped file's name.
    base_dir : Path
        The folder a relative path is taken from.
    kind : str
        ``"circuit"``, ``"experiment"`` or ``"invariance"``.
    source : str
        The file named in a message.
    key : str or None
        The key named in a message.

    Returns
    -------
    Path
        The file.
    """
    text = os.fspath(value)
    path = Path(base_dir) / text
    seps = tuple(s for s in (os.sep, os.altsep) if s)
    shipped = shipped_files(kind)
    existing = path.exists() and not (path.is_dir() and text in shipped)
    if existing or text.endswith(".toml") or any(s in text for s in seps) or not text:
        return path
    if text in shipped:
        return shipped[text]
    other = next((k for k in SHIPPED if k != kind and text in shipped_files(k)), None)
    got = f"{text!r} (a shipped {other} file: 'neurocur list' says how to use it)" if other else \
        f"{text!r} (no such file or name)"
    raise ConfigError(source, key, f"an existing {kind} file or the name of a shipped {kind} "
                                   f"({', '.join(shipped) or 'none'})", got)
