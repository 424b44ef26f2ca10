"""The error of a results folder that cannot be read or resumed as it is."""

__all__ = ["ResultsError"]


class ResultsError(ValueError):
    """A results folder that cannot be read or resumed as it is (the message says why and what to do)."""
