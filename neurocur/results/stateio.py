"""A state folder on disk: written atomically with the digests that prove it, read back only when it does.

A state folder (a checkpoint, a saved agent: :mod:`.agents`) holds two files:

* ``state.json``: ``{"format", "version", "meta", "roots", "arrays", "sha256"}``; ``roots`` is the
  walker's encoding (:mod:`.statefile`), ``arrays`` declares each array's dtype and shape, and
  ``sha256`` holds the digest of ``arrays.npz`` and of the rest of ``state.json`` (its canonical
  JSON: sorted keys, no spaces);
* ``arrays.npz``: the arrays by key.

:func:`write_state` writes both into a temporary folder beside ``folder``
(``.<name>.<pid>.tmp``, never through a link: :func:`~.safeio.open_new`) and moves it into
place with one rename. :func:`read_state` trusts nothing it reads: the folder and its two
files must be real (no link is followed: :func:`~.safeio.real_dir`, :func:`~.safeio.read_own`),
both digests must match, ``arrays.npz`` is read with ``allow_pickle=False`` and every array
must have the declared dtype and shape (no object array). Anything else is a
:class:`StateError` of one line naming the file and what did not match; nothing has been
decoded yet.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
import zipfile
import zlib
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .safeio import UnsafePath, open_new, open_real_dir, read_own, remove_own

__all__ = ["ARRAYS", "FORMAT", "STATE", "VERSION", "StateError", "debris", "read_state", "write_state"]

FORMAT = "neurocur-state"
#: 2: ``state.json`` declares its arrays and carries the digests (version 1 did neither)
VERSION = 2
#: the state folder's JSON file (body, digests)
STATE = "state.json"
#: the state folder's arrays
ARRAYS = "arrays.npz"
_DEBRIS = re.compile(r"\.(.+)\.\d+\.(?:tmp|old)")


class StateError(ValueError):
    """State that cannot be saved (an object the walker does not take) or a state folder that cannot be loaded."""


def write_state(folder, body: Mapping, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write a state (``body``: ``state.json``'s content without ``arrays`` and ``sha256``, which are
    added here) into ``folder`` atomically; returns ``folder``.

    Parameters
    ----------
    folder : path
        The state folder; an existing one (or a link in its place) is moved aside and removed, never followed.
    body : mapping
        ``state.json``'s content without ``arrays`` and ``sha256``.
    arrays : mapping of str to numpy.ndarray
        The arrays by key, written as ``arrays.npz``.

    Returns
    -------
    path
        ``folder``.
    """
    folder = Path(folder)
    arrays = {key: np.asarray(value) for key, value in arrays.items()}
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    data = buffer.getvalue()
    body = {**body, "arrays": {key: {"dtype": a.dtype.str, "shape": list(a.shape)} for key, a in arrays.items()}}
    body["sha256"] = {"state": _json_digest(body), ARRAYS: hashlib.sha256(data).hexdigest()}
    tmp = folder.with_name(f".{folder.name}.{os.getpid()}.tmp")
    remove_own(tmp)
    os.mkdir(tmp)
    try:
        for name, content in ((ARRAYS, data), (STATE, (json.dumps(body) + "\n").encode("utf-8"))):
            with os.fdopen(open_new(tmp / name), "wb") as fh:
                fh.write(content)
        old = folder.with_name(f".{folder.name}.{os.getpid()}.old")
        if os.path.lexists(folder):
            remove_own(old)
            os.replace(folder, old)  # a link is moved aside as a link, never followed
        os.replace(tmp, folder)
        remove_own(old)
    except BaseException:
        remove_own(tmp)
        raise
    return folder


def debris(parent: Path, name: str | None = None) -> list[Path]:
    """The temporary folders that :func:`write_state` leaves in ``parent`` when its process is killed
    while it writes the state folder ``name`` (any name when None): ``.<name>.<pid>.tmp`` and
    ``.<name>.<pid>.old``.

    Parameters
    ----------
    parent : path
        The folder holding state folders (empty list when it is a link or no folder).
    name : str, optional
        The state folder's name; None: any.

    Returns
    -------
    list of path
        The temporary folders, sorted.
    """
    if parent.is_symlink() or not parent.is_dir():
        return []
    found = (_DEBRIS.fullmatch(p.name) for p in parent.iterdir())
    return sorted(parent / m.group(0) for m in found if m is not None and name in (None, m.group(1)))


def read_state(folder) -> tuple[dict, dict[str, np.ndarray]]:
    """``(body, arrays)`` of the state folder ``folder``, every check of the module docstring passed
    (``body`` without its ``sha256``).

    Parameters
    ----------
    folder : path
        The state folder.

    Returns
    -------
    (dict, dict)
        ``state.json``'s content without ``sha256``, and the arrays by key.

    Raises
    ------
    StateError
        When a check fails, naming the file and what did not match.
    """
    folder = Path(folder)
    try:
        fd = open_real_dir(folder)
    except (UnsafePath, OSError) as exc:
        raise StateError(str(exc) if isinstance(exc, UnsafePath) else f"{folder}: {_reason(exc)}") from None
    if fd is None:
        raise StateError(f"{folder}: expected a state folder written by neurocur, got nothing")
    try:
        return _read(folder, fd)
    finally:
        os.close(fd)


def _read(folder: Path, fd: int) -> tuple[dict, dict[str, np.ndarray]]:
    try:
        text = read_own(folder / STATE, dir_fd=fd)
    except UnsafePath as exc:
        raise StateError(str(exc)) from None
    except OSError as exc:
        raise StateError(f"{folder / STATE}: expected a state file written by neurocur, got {_reason(exc)}") from None
    body = _body(folder / STATE, text)
    digests = body.pop("sha256", None)
    if not isinstance(digests, dict) or digests.get("state") != _json_digest(body):
        raise StateError(f"{folder / STATE}: key 'sha256.state': expected the sha256 of the state as written, got "
                         "another (the file was changed after it was written)")
    try:
        data = read_own(folder / ARRAYS, dir_fd=fd)
    except UnsafePath as exc:
        raise StateError(str(exc)) from None
    except OSError as exc:
        raise StateError(f"{folder / ARRAYS}: expected the arrays written with {STATE}, got {_reason(exc)}") from None
    if hashlib.sha256(data).hexdigest() != digests.get(ARRAYS):
        raise StateError(f"{folder / ARRAYS}: expected the sha256 that {STATE} records, got another (the file was "
                         "changed or cut short after it was written)")
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as npz:
            arrays = {key: npz[key] for key in npz.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as exc:
        raise StateError(f"{folder / ARRAYS}: expected numpy arrays without objects, got {_reason(exc)}") from None
    _check_declared(folder / ARRAYS, body.get("arrays"), arrays)
    return body, arrays


def _body(path: Path, text: bytes) -> dict:
    try:
        body = json.loads(text.decode("utf-8"))
    except ValueError as exc:
        raise StateError(f"{path}: expected a state file written by neurocur (JSON), got {exc}") from None
    if not isinstance(body, dict):
        raise StateError(f"{path}: expected a JSON object, got a {type(body).__name__}")
    if body.get("format") != FORMAT:
        raise StateError(f"{path}: key 'format': expected {FORMAT!r}, got {body.get('format')!r}")
    if body.get("version") != VERSION:
        raise StateError(f"{path}: key 'version': expected {VERSION} (this neurocur's state format), "
                         f"got {body.get('version')!r}")
    for key, kind in (("meta", dict), ("roots", dict), ("arrays", dict)):
        if not isinstance(body.get(key), kind):
            raise StateError(f"{path}: key '{key}': expected a JSON object, got {body.get(key)!r:.40}")
    return body


def _check_declared(path: Path, declared: Mapping, arrays: Mapping[str, np.ndarray]) -> None:
    """Every array has the dtype and shape that ``state.json`` declares, and is no object array."""
    if set(declared) != set(arrays):
        raise StateError(f"{path}: expected the arrays {sorted(declared)[:5]}... that {STATE} declares, got "
                         f"{sorted(set(arrays) ^ set(declared))[:5]} too many or missing")
    for key, array in arrays.items():
        want = declared[key]
        if array.dtype.hasobject or not isinstance(want, dict) or want.get("dtype") != array.dtype.str \
                or want.get("shape") != list(array.shape):
            raise StateError(f"{path}: array {key!r}: expected dtype {want.get('dtype') if isinstance(want, dict) else '?'} "
                             f"and shape {want.get('shape') if isinstance(want, dict) else '?'} as {STATE} declares, "
                             f"got {array.dtype.str} {list(array.shape)}")


def _json_digest(body: Mapping) -> str:
    return hashlib.sha256(json.dumps(body, sort_keys=True, separators=(",", ":")).encode("utf-8")).hexdigest()


def _reason(exc: BaseException) -> str:
    if isinstance(exc, FileNotFoundError):
        return "no such file"
    return f"{type(exc).__name__}: {exc.strerror if isinstance(exc, OSError) and exc.strerror else exc}"
