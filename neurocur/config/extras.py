"""Optional dependencies: a feature whose package is not installed names the extra to install.

The base install (``pip install neurocur``) runs the synthetic experiment, the analysis and
the figures. The heavier features live in extras of ``pyproject.toml``: ``icub`` (MuJoCo and
the iCub's meshes), ``cluster`` (dask.distributed), ``gym`` (gymnasium's rendering
environments, pygame), ``rl`` (stable-baselines3) and ``fit`` (sbi, torch). Each import of
such a package sits inside :func:`extra`, which turns a missing module into a one-line
:class:`MissingExtra` (a ``ValueError``, so the command line exits with status 2)::

    with extra("cluster", "--scheduler"):
        import dask
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["MissingExtra", "extra"]


class MissingExtra(ImportError, ValueError):
    """A feature needs a package that is not installed; the message names the extra to install.

    An ``ImportError`` (callers that probe for a package catch it) and a ``ValueError`` (the
    command line reports it in one line, exit status 2)."""


@contextmanager
def extra(name: str, feature: str) -> Iterator[None]:
    """Run the imports of the block; a missing module raises :class:`MissingExtra` naming the
    extra ``name`` of the feature ``feature`` (e.g. ``"the iCub world"``).

    Parameters
    ----------
    name : str
        The extra to install (``pip install neurocur[name]``).
    feature : str
        What needs it, named in the message.
    """
    try:
        yield
    except ModuleNotFoundError as exc:
        raise MissingExtra(f"{feature} needs the Python package {exc.name!r}, which is not installed: "
                           f"pip install 'neurocur[{name}]'", name=exc.name) from None
