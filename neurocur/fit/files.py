"""Reading a data file a user names: never through a link, never blocking on a FIFO, one line for what is wrong.

Every reader of the fit layer (episode tables, :mod:`.data`; trial tables, :mod:`.trials`; the posted files
of Ten et al. 2021, :mod:`.ten2021`) goes through :func:`path_kind` and :func:`read_table`, so a symbolic
link, a FIFO, a device, bytes that are not UTF-8, an empty file or a table that does not parse are each a
:class:`~neurocur.config.ConfigError` naming the file and what was expected.
"""

from __future__ import annotations

import io
import os
import stat
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from ..config import ConfigError

__all__ = ["PARQUET_SUFFIXES", "path_kind", "read_bytes", "read_table"]

#: Suffixes read as Parquet; every other accepted suffix is delimited text.
PARQUET_SUFFIXES = (".parquet", ".pq")


def path_kind(path: Path, expected: str) -> str:
    """``"folder"`` or ``"file"`` for a real folder or a regular file at ``path`` (never following a link);
    anything else is a ConfigError saying ``expected``.

    Parameters
    ----------
    path : path
        The path given.
    expected : str
        What the path should be, for the message.

    Returns
    -------
    str
        ``"folder"`` or ``"file"``.
    """
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        raise ConfigError(path, None, expected, "no such path") from None
    except OSError as exc:
        raise ConfigError(path, None, expected, exc.strerror or str(exc)) from None
    if stat.S_ISDIR(mode):
        return "folder"
    if stat.S_ISLNK(mode):
        raise ConfigError(path, None, f"{expected} (a symbolic link is never followed)", "a symbolic link")
    if not stat.S_ISREG(mode):
        raise ConfigError(path, None, expected, _special(mode))
    return "file"


def read_bytes(path: Path, expected: str) -> bytes:
    """The bytes of the regular file at ``path``, opened without following a link and without blocking on a
    FIFO (its type is checked on the open descriptor, so a file swapped after :func:`path_kind` is caught).

    Parameters
    ----------
    path : path
        The file.
    expected : str
        What the file should be, for the message.

    Returns
    -------
    bytes
        The file's content.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise ConfigError(path, None, expected, "no such file") from None
    except OSError as exc:
        got = "a symbolic link" if os.path.islink(path) else exc.strerror or str(exc)
        raise ConfigError(path, None, f"{expected} (a symbolic link is never followed)", got) from None
    with os.fdopen(fd, "rb") as handle:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise ConfigError(path, None, expected, _special(mode))
        os.set_blocking(fd, True)
        return handle.read()


def read_table(path: Path, suffixes: Sequence[str], expected: str, *, header: str = "", **read_csv) -> pd.DataFrame:
    """The table at ``path``: Parquet (:data:`PARQUET_SUFFIXES`) or UTF-8 delimited text, whose delimiter is a
    tab when the header line has one, else a comma.

    Parameters
    ----------
    path : path
        The file.
    suffixes : sequence of str
        The suffixes accepted.
    expected : str
        What the file should be, for the messages.
    header : str
        The columns a header row should name (for an empty file's message).
    **read_csv
        Further arguments of :func:`pandas.read_csv`.

    Returns
    -------
    pandas.DataFrame
        The table as read.
    """
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        raise ConfigError(path, None, expected, f"suffix '{path.suffix}'")
    data = read_bytes(path, expected)
    if suffix in PARQUET_SUFFIXES:
        try:
            return pd.read_parquet(io.BytesIO(data))
        except (ValueError, OSError) as exc:
            raise ConfigError(path, None, "a Parquet table", _first_line(exc)) from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(path, None, "UTF-8 text", f"the byte 0x{exc.object[exc.start]:02x} at offset "
                          f"{exc.start}") from None
    first = text.split("\n", 1)[0]
    try:
        return pd.read_csv(io.StringIO(text), sep="\t" if "\t" in first else ",", **read_csv)
    except pd.errors.EmptyDataError:
        raise ConfigError(path, None, f"a table with a header row{f' ({header})' if header else ''}",
                          "an empty file") from None
    except (pd.errors.ParserError, ValueError) as exc:
        raise ConfigError(path, None, "a delimited text table", _first_line(exc)) from None


def _special(mode: int) -> str:
    return "a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device or special file"


def _first_line(exc: Exception) -> str:
    return f"{type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}"
