"""Configuration errors that name the file, the dotted key and what was expected."""

from __future__ import annotations

__all__ = ["ConfigError", "describe", "join_key"]


def describe(value) -> str:
    """Short description of a configuration value for error messages: ``-1 (int)``.

    Parameters
    ----------
    value : object
        The value.

    Returns
    -------
    str
        Its short description.
    """
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{text} ({type(value).__name__})"


class ConfigError(ValueError):
    """A configuration error that names the file, the dotted key and what was expected.

    ``source`` is the file (or a label such as ``"<python>"``), ``key`` the dotted key
    (``None`` for the whole file), ``expected`` what would have been valid, ``got`` what
    was found (already described as text).

    Parameters
    ----------
    source : str or Path
        The file, or a label such as ``"<python>"``.
    key : str or None
        The dotted key (None for the whole file).
    expected : str
        What would have been valid.
    got : str
        What was found, described as text (:func:`describe`).
    """

    def __init__(self, source, key: str | None, expected: str, got: str):
        self.source = str(source)
        self.key = key
        self.expected = expected
        self.got = got
        where = f"{self.source}: key '{key}'" if key else self.source
        super().__init__(f"{where}: expected {expected}, got {got}")

    def __reduce__(self):  # pickled as its four parts (a worker process raises it to its parent)
        return type(self), (self.source, self.key, self.expected, self.got)

    def relocated(self, source=None, prefix: str | None = None) -> ConfigError:
        """The same error reported from another file and/or under a key prefix."""
        key = join_key(prefix, self.key) if prefix else self.key
        return ConfigError(self.source if source is None else source, key, self.expected, self.got)


def join_key(prefix: str, key: str | None) -> str:
    """``prefix.key``; an index key (``[2]``) attaches without a dot; either part may be empty.

    Parameters
    ----------
    prefix : str
        The table's dotted path.
    key : str or None
        The key within it.

    Returns
    -------
    str
        The joined key.
    """
    if not prefix or not key:
        return key or prefix
    return f"{prefix}{key}" if key.startswith("[") else f"{prefix}.{key}"
