"""Argument types of the command line, shared by ``neurocur`` and its fit layer's subcommands: a value is
checked by argparse, before any folder is made, and a bad one is argparse's one-line usage error."""

from __future__ import annotations

import argparse
import re

__all__ = ["int_at_least", "mca_eta", "memory_size"]


def int_at_least(low: int, expected: str):
    """An argparse type: an integer >= ``low``; the error says ``expected``.

    Parameters
    ----------
    low : int
        The smallest integer accepted.
    expected : str
        What the error message says was expected.

    Returns
    -------
    callable
        The argparse type: a string to its integer.
    """
    def convert(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low:
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
        return value

    return convert


def mca_eta(text: str) -> float:
    """An argparse type: an MCA learning rate η in (0, 0.5] (Ω's, paper eqs 15 and 40).

    Parameters
    ----------
    text : str
        The command line's value.

    Returns
    -------
    float
        The learning rate.
    """
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number in (0, 0.5], got {text!r}") from None
    if not 0.0 < value <= 0.5:
        raise argparse.ArgumentTypeError(f"expected a number in (0, 0.5], got {text!r}")
    return value


def memory_size(text: str) -> int:
    """An argparse type: a memory size such as ``8G``, ``512M`` or ``1.5GiB``, in bytes (powers of 1024).

    Parameters
    ----------
    text : str
        The command line's value.

    Returns
    -------
    int
        The size in bytes.
    """
    match = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*([kmgt]?)i?b?\s*", text.lower())
    if not match or float(match.group(1)) <= 0:
        raise argparse.ArgumentTypeError(f"expected a memory size such as 8G or 512M, got {text!r}")
    return int(float(match.group(1)) * 1024 ** " kmgt".index(match.group(2) or " "))
