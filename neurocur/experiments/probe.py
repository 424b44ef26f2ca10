"""Checking a Dask scheduler's address before a client connects to it.

``dask.distributed`` retries a connection for its whole timeout, and waits without limit for
a handshake from a listener that accepts the connection and then says nothing (an HTTP
server, a silent port): ``--scheduler tcp://HOST:PORT`` pointing at something else would
hang without output. :func:`probe_scheduler` connects with a timeout and reads the first
message a Dask comm sends on every new connection, its handshake (a frame of
msgpack holding ``compression``, ``python`` and ``pickle-protocol``), within a timeout.
"""

from __future__ import annotations

import socket
import struct

__all__ = ["probe_scheduler"]

#: the longest handshake message accepted (a real one is under a hundred bytes)
_MAX_HANDSHAKE = 1 << 16


def probe_scheduler(address: str, timeout: float = 5.0) -> None:
    """ValueError (one line) unless a Dask scheduler answers at ``address`` (``tcp://HOST:PORT`` or
    ``HOST:PORT``) within ``timeout`` seconds; other protocols are left to Dask.

    Parameters
    ----------
    address : str
        ``--scheduler``'s address.
    timeout : float
        Seconds to connect, and again to receive the handshake.

    Raises
    ------
    ValueError
        For an address that is not ``HOST:PORT``, nothing listening, or a listener that does not send a
        Dask handshake in time.
    """
    scheme, sep, rest = address.partition("://")
    if sep and scheme != "tcp":
        return
    host, _, port = (rest if sep else address).rpartition(":")
    if not host or not port.isdigit():
        raise ValueError(f"--scheduler {address}: expected 'local' or a scheduler's address tcp://HOST:PORT")
    expected = f"--scheduler {address}: expected a reachable dask.distributed scheduler"
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout) as conn:
            conn.settimeout(timeout)
            header = _read(conn, 8)
            (size,) = struct.unpack("<Q", header)
            message = _read(conn, size) if 0 < size <= _MAX_HANDSHAKE else b""
    except TimeoutError:
        raise ValueError(f"{expected}, got a listener that sent no Dask handshake within {timeout:g} s "
                         "(another kind of server?)") from None
    except OSError as exc:
        raise ValueError(f"{expected}, got {exc.strerror or exc}") from None
    if b"compression" not in message or b"python" not in message:
        raise ValueError(f"{expected}, got a server that does not speak the Dask protocol "
                         f"(it sent {header[:8]!r}...)")


def _read(conn: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = conn.recv(n - len(data))
        if not chunk:
            raise ConnectionResetError("the connection closed before a Dask handshake")
        data += chunk
    return data
