"""The keys of the tidy tables: the columns that identify a run, and contexts by index or by name.

Every per-run or per-episode table of the statistics carries ``condition``, ``run`` and, for a
sweep, one column per swept key (:func:`~neurocur.analysis.stats.order.sweep_columns`):
:func:`run_keys` names them, for the modules that group by run (dwell, efficiency, event-locked
averages, learning cycles). Contexts are indices in the tables; a ``spec`` (a
:class:`~neurocur.contexts.base.SourceSpec`, or one per condition as
:func:`~neurocur.analysis.io.source_specs` returns) names them and their sources:
:func:`spec_of` picks a condition's, and :func:`context_indices` reads contexts given by index
or by name.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from neurocur.contexts.base import SourceSpec

from .order import sweep_columns

__all__ = ["Spec", "run_keys", "spec_of", "context_indices"]

#: The sources of the world (one ``SourceSpec``), or of each condition's world by condition name, or None.
Spec = SourceSpec | Mapping[str, SourceSpec] | None


def run_keys(table: pd.DataFrame) -> list[str]:
    """The columns that identify a run: condition, run and the swept keys of a sweep.

    Parameters
    ----------
    table : pandas.DataFrame
        A tidy table with ``condition`` and ``run``.

    Returns
    -------
    list of str
        ``["condition", "run", *swept keys]``.
    """
    return ["condition", "run", *sweep_columns(table)]


def spec_of(spec: Spec, condition: str) -> SourceSpec | None:
    """The :class:`SourceSpec` of ``condition``: ``spec`` itself, or its entry in a per-condition mapping.

    Parameters
    ----------
    spec : SourceSpec or mapping of str to SourceSpec, optional
        The sources of the world, or of each condition's world by condition name.
    condition : str
        The condition.

    Returns
    -------
    SourceSpec or None
        The condition's sources; None when ``spec`` is None.

    Raises
    ------
    ValueError
        When ``spec`` is a mapping without ``condition``.
    """
    if spec is None or isinstance(spec, SourceSpec):
        return spec
    if condition not in spec:
        raise ValueError(f"no source spec for condition {condition!r}; have {sorted(spec)}")
    return spec[condition]


def context_indices(contexts, spec: SourceSpec | None, *, needed_by: str) -> list[int]:
    """Context indices of ``contexts`` (indices, or names of ``spec``'s contexts).

    Parameters
    ----------
    contexts : int, str or sequence of int or str
        The contexts: indices, or names of ``spec``'s contexts.
    spec : SourceSpec or None
        The sources of the world; None: only indices are accepted.
    needed_by : str
        What asks, named in the message of an unknown context.

    Returns
    -------
    list of int
        The indices, in the order given.

    Raises
    ------
    ValueError
        When a context is neither an index nor a name of ``spec``'s contexts.
    """
    items = [contexts] if isinstance(contexts, (str, int, np.integer)) else list(contexts)
    out = []
    for item in items:
        if isinstance(item, (int, np.integer)):
            out.append(int(item))
        elif spec is not None and item in spec.context_names:
            out.append(spec.context_names.index(item))
        else:
            have = "no spec to name contexts" if spec is None else f"contexts {list(spec.context_names)}"
            raise ValueError(f"{needed_by}: unknown context {item!r}; give an index or a name ({have})")
    return out
