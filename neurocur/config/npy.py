"""Reading a user's ``.npy`` file: its header checked against the file before any array is made.

``numpy.load`` allocates what a ``.npy`` header claims before it reads the data, so a header
claiming a 72 TiB shape ends in a MemoryError (or the system's out-of-memory killer).
:func:`load_npy` reads the header first and refuses a file whose data is shorter than its
header says, and never unpickles (object arrays are refused).
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["load_npy"]


def load_npy(path) -> np.ndarray:
    """The array of the ``.npy`` file ``path``; ValueError (one line) for a file that is not a
    ``.npy`` array (a ``.npz`` archive included), holds objects, or whose data is shorter than its
    header claims.

    Parameters
    ----------
    path : str or Path
        The ``.npy`` file.

    Returns
    -------
    numpy.ndarray
        Its array.
    """
    with open(path, "rb") as fh:
        if fh.read(4) == b"PK\x03\x04":
            raise ValueError("expected a .npy array written by numpy.save, got a .npz archive")
        fh.seek(0)
        try:
            version = np.lib.format.read_magic(fh)
            read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, _, dtype = read(fh, max_header_size=10000)
        except (ValueError, EOFError, SyntaxError) as exc:
            raise ValueError(f"expected a .npy array written by numpy.save, got a file numpy cannot read as one "
                             f"({exc})") from None
        if dtype.hasobject:
            raise ValueError("expected a .npy array of numbers, got an array of Python objects (never unpickled)")
        claimed = int(np.prod(shape, dtype=object)) * dtype.itemsize
        left = os.fstat(fh.fileno()).st_size - fh.tell()
        if claimed > left:
            raise ValueError(f"expected a .npy file holding the {claimed} bytes its header claims (shape {shape}, "
                             f"{dtype}), got {left} bytes of data")
    return np.load(path, allow_pickle=False)
