"""Writing inside a results folder without following a link the store did not make.

Every file the store writes (the lock, ``config.toml``, ``summary.json``, a run's tables)
lies inside the results folder ``OUT``, and every folder on the way from ``OUT`` to it is
a real directory: :func:`own_dir` creates it or checks it (a symbolic link, a file or a
FIFO in its place is refused), and :func:`open_new` opens a file with ``O_NOFOLLOW`` (and
``O_EXCL`` for a temporary file), so a link planted at any of these names is never
written through. What the store reads back as state it trusts (a checkpoint, a saved agent)
is read the same way: :func:`real_dir` checks a folder and :func:`open_real_dir` opens one,
:func:`read_own` reads a file with ``O_NOFOLLOW`` (relative to its opened folder). ``OUT`` itself is the user's choice and may be a link.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
from pathlib import Path

__all__ = ["UnsafePath", "atomic_bytes", "atomic_text", "open_new", "open_real_dir", "own_dir", "read_own", "real_dir",
           "remove_own"]


class UnsafePath(ValueError):
    """A name inside a results folder that is a link, or not the kind of file the store writes there."""


def own_dir(root: Path, *parts: str) -> Path:
    """``root/parts...``, each level created when missing and refused unless it is a real directory.

    ``root`` must exist (the store never re-creates a results folder that was moved or
    removed while it ran, see :meth:`ResultsStore.write_run`).

    Parameters
    ----------
    root : path
        An existing directory.
    *parts : str
        The levels below it.

    Returns
    -------
    path
        ``root/parts...``.
    """
    path = Path(root)
    if not path.is_dir():
        raise UnsafePath(f"results folder {root} does not exist any more (moved or removed while runs were being "
                         "written?); nothing was written")
    for part in parts:
        path = path / part
        try:
            os.mkdir(path)
        except FileExistsError:
            mode = os.lstat(path).st_mode
            if not stat.S_ISDIR(mode):
                kind = "a symbolic link" if stat.S_ISLNK(mode) else "not a directory"
                raise UnsafePath(f"{path}: expected a folder written by neurocur, got {kind}; "
                                 "the store never follows a link it did not make (remove it)") from None
    return path


def open_new(path: Path, *, exclusive: bool = True) -> int:
    """A file descriptor for writing ``path`` (created), never through a symbolic link.

    ``exclusive``: the file must not exist yet (a temporary name). Otherwise an existing
    file is opened only when it is a regular file with no other hard link.

    Parameters
    ----------
    path : path
        The file.
    exclusive : bool
        The file must not exist yet.

    Returns
    -------
    int
        The file descriptor.
    """
    flags = os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK | (os.O_EXCL if exclusive else 0)
    try:
        fd = os.open(path, flags, 0o644)
    except OSError:
        if os.path.islink(path):
            raise UnsafePath(f"{path} is a symbolic link; the store never follows a link it did not make "
                             "(remove it)") from None
        raise
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode) or info.st_nlink != 1:
        os.close(fd)
        why = "has another hard link" if stat.S_ISREG(info.st_mode) else "is not a regular file"
        raise UnsafePath(f"{path} {why}; the store writes only files it made (remove it)")
    os.set_blocking(fd, True)
    return fd


def real_dir(path: Path) -> bool:
    """Whether ``path`` is a real directory (False when it does not exist); UnsafePath for a link or
    anything else in its place.

    Parameters
    ----------
    path : path
        The path checked.

    Returns
    -------
    bool
        Whether it is a real directory.
    """
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return False
    if not stat.S_ISDIR(mode):
        kind = "a symbolic link" if stat.S_ISLNK(mode) else "not a directory"
        raise UnsafePath(f"{path}: expected a folder written by neurocur, got {kind}; the store never follows "
                         "a link it did not make")
    return True


def open_real_dir(path: Path) -> int | None:
    """A file descriptor of the real directory ``path``, opened with ``O_NOFOLLOW`` (None when it does not
    exist; UnsafePath for a link or anything else in its place): the files in it are then opened
    relative to it (:func:`read_own`'s ``dir_fd``), so the folder cannot be swapped for a link meanwhile.

    Parameters
    ----------
    path : path
        The directory.

    Returns
    -------
    int or None
        The directory's file descriptor, or None.
    """
    try:
        return os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
    except FileNotFoundError:
        return None
    except OSError:
        real_dir(path)  # names a link or a file
        raise


def read_own(path: Path, *, dir_fd: int | None = None) -> bytes:
    """The content of the regular file ``path`` (with ``dir_fd``: its name in that directory), opened with
    ``O_NOFOLLOW`` (UnsafePath for a link or anything but a regular file; OSError when it cannot be read).

    Parameters
    ----------
    path : path
        The file.
    dir_fd : int, optional
        A directory's descriptor (:func:`open_real_dir`); ``path`` is then a name in it.

    Returns
    -------
    bytes
        The file's content.
    """
    try:
        fd = os.open(Path(path).name if dir_fd is not None else path,
                     os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, dir_fd=dir_fd)
    except OSError:
        try:
            mode = os.lstat(Path(path).name if dir_fd is not None else path, dir_fd=dir_fd).st_mode
        except OSError:
            mode = 0
        if stat.S_ISLNK(mode):
            raise UnsafePath(f"{path} is a symbolic link; the store never follows a link it did not make") from None
        raise
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise UnsafePath(f"{path} is not a regular file; the store reads only files it wrote")
        os.set_blocking(fd, True)
        return fh.read()


def remove_own(path: Path) -> None:
    """Remove ``path`` if it exists: a real folder with its content, anything else (a link: the link
    itself, never what it points to) by unlinking it.

    Parameters
    ----------
    path : path
        The path removed.
    """
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if stat.S_ISDIR(mode):
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)


def atomic_text(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) into ``path`` atomically (:func:`atomic_bytes`).

    Parameters
    ----------
    path : path
        The file.
    text : str
        The content.
    """
    atomic_bytes(path, text.encode("utf-8"))


def atomic_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` into ``path`` atomically: a new temporary file beside it, then one rename (which
    replaces a link planted at ``path``, never writes through it).

    The temporary file is removed when writing fails (a full disk, ``ulimit -f``).

    Parameters
    ----------
    path : path
        The file.
    data : bytes
        The content.
    """
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        os.unlink(tmp)  # a leftover of this pid's previous life; never a link to follow
    except FileNotFoundError:
        pass
    fd = open_new(tmp)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        if isinstance(exc, OSError) and exc.filename is None:  # a failed write names no file by itself
            raise OSError(exc.errno, f"cannot write {path}: {exc.strerror}") from None
        raise
