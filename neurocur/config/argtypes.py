"""Argument types of the command line, shared by ``neurocur`` and its fit layer's subcommands: a value is
checked by argparse, before any folder is made, and a bad one is argparse's one-line usage error."""

from __future__ import annotations

import argparse

__all__ = ["int_at_least"]


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
