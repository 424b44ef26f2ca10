"""An exclusive lock on a results folder while a process writes to it.

``OUT/.lock`` is locked with ``fcntl.flock`` (non-blocking) and holds its holder's pid,
host, start time and command as JSON, so a second writer is refused with a message
naming the holder. The operating system releases a flock when its process ends, however
it ends, so a lock left by a killed process never blocks: the next writer takes it and
finds the dead holder's details in the file (:attr:`FolderLock.stale`). A released lock
removes its file. Within one process the lock is re-entrant. Reading a results folder
needs no lock (runs are written atomically).

The lock file is opened without following a link (:func:`~neurocur.results.safeio.open_new`):
a ``.lock`` that is a symbolic link, a hard link to another file or not a regular file
is refused, never truncated.
"""

from __future__ import annotations

import fcntl
import json
import os
import socket
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .safeio import open_new

__all__ = ["LOCK", "FolderInUse", "FolderLock", "locked"]

LOCK = ".lock"

#: the locks this process holds, by the folder's real path
_HELD: dict[str, FolderLock] = {}


class FolderInUse(ValueError):
    """Another process holds the results folder's lock."""


class FolderLock:
    """The lock of one results folder; take it with :func:`locked`.

    Parameters
    ----------
    root : path
        The results folder.
    """

    def __init__(self, root):
        self.root = Path(root)
        self.path = self.root / LOCK
        #: the holder details left by a process that ended without releasing the lock, else None
        self.stale: dict | None = None
        self._fd: int | None = None
        self._depth = 0
        self._created = False

    def _take(self) -> None:
        self._created = not self.root.exists()
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except FileExistsError:
            raise ValueError(f"results folder {self.root}: expected a folder, got a file") from None
        except OSError as exc:
            raise ValueError(f"results folder {self.root}: cannot create it ({exc.strerror or exc})") from None
        while True:
            try:
                fd = open_new(self.path, exclusive=False)
            except OSError as exc:
                raise ValueError(f"results folder {self.root}: cannot write into it ({exc.strerror or exc})") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = _read(fd)
                os.close(fd)
                raise FolderInUse(f"results folder {self.root} is in use: {describe_holder(holder)} is writing to it; "
                                  "wait for it to finish or use another --out folder") from None
            if _same_file(fd, self.path):
                break
            os.close(fd)  # the holder released (and removed) the file between our open and flock: retry
        self._fd = fd
        self.stale = _read(fd) or None
        info = {"pid": os.getpid(), "host": socket.gethostname(),
                "started": time.strftime("%Y-%m-%d %H:%M:%S %z"), "command": " ".join(sys.argv)}
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(info) + "\n").encode(), 0)

    def _release(self) -> None:
        try:
            os.unlink(self.path)  # while still holding it, so that no one locks the removed file
        except OSError:  # gone, or the folder was made read-only: a lock file nobody holds never blocks
            pass
        fcntl.flock(self._fd, fcntl.LOCK_UN)
        os.close(self._fd)
        self._fd = None
        if self._created:  # a folder made for nothing (e.g. the experiment failed its checks) goes again
            try:
                self.root.rmdir()
            except OSError:
                pass


@contextmanager
def locked(root) -> Iterator[FolderLock]:
    """Hold the lock of the results folder ``root`` (created if needed) for the ``with`` block.

    Raises :class:`FolderInUse` (naming the holder) when another process holds it, and
    ValueError when ``root`` is a file or cannot be written. Re-entrant within a process.

    Parameters
    ----------
    root : path
        The results folder.

    Yields
    ------
    FolderLock
        The lock held.
    """
    key = os.path.realpath(root)
    lock = _HELD.get(key)
    if lock is None:
        lock = FolderLock(root)
        lock._take()
        _HELD[key] = lock
    lock._depth += 1
    try:
        yield lock
    finally:
        lock._depth -= 1
        if lock._depth == 0:
            del _HELD[key]
            lock._release()


def describe_holder(info: dict | None) -> str:
    """``"pid 123 on host (since ..., running '...')"`` from a lock file's details."""
    if not info:
        return "another process"
    text = f"pid {info.get('pid', '?')} on {info.get('host', '?')}"
    if info.get("started"):
        text += f" (since {info['started']}"
        text += f", running '{info['command']}')" if info.get("command") else ")"
    return text


def _read(fd: int) -> dict:
    try:
        data = os.pread(fd, 65536, 0).decode("utf-8", "replace").strip()
        info = json.loads(data) if data else {}
    except (OSError, ValueError):
        return {}
    return info if isinstance(info, dict) else {}


def _same_file(fd: int, path: Path) -> bool:
    try:
        now = os.stat(path)
    except FileNotFoundError:
        return False
    held = os.fstat(fd)
    return (held.st_dev, held.st_ino) == (now.st_dev, now.st_ino)
