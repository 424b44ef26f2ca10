"""Behaviour data: a tidy table of episodes, one row per decision, read from CSV, Parquet or a results folder.

Columns (design section 7; Wilson & Collins 2019 for the workflow it serves):

- ``dataset``: the subject or run the episode belongs to (any label; a results folder's
  runs are named ``"CONDITION/RUN"``);
- ``episode``: the episode's index within its data set, strictly increasing;
- ``context``: the context shown, an index or one of the world's context names;
- ``decision``: what was decided at the end of the episode: ``"engage"``/``"disengage"``
  (or 0/1) in an engage/disengage task, the chosen context (index or name) in a
  free-choice task;
- optional further columns, per-episode signals the model would otherwise compute itself
  (an error or accuracy per episode, for signal replay, :mod:`neurocur.fit.replay`).

Bad data is a :class:`~neurocur.config.ConfigError` naming the file, the column and what
was expected (a missing column, an unknown context, episodes out of order, a missing value,
a signal that is not a finite number, a data set named as the outputs name the pooled fit).
The path itself must be a regular file or a results folder: a symbolic link is never
followed and a FIFO or device is refused before it is read (reading one would block or
read something other than a table); a file that is not UTF-8 text, or is empty, is named.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import ConfigError
from ..regions.pfc import ACTIONS
from ..results import ResultsStore
from .files import PARQUET_SUFFIXES, path_kind, read_table

__all__ = ["Behaviour", "REQUIRED", "RESERVED", "read_behaviour", "behaviour_from_episodes"]

#: The columns every behaviour table has.
REQUIRED = ("dataset", "episode", "context", "decision")
#: data set names the fit commands' outputs give rows of their own (the pooled fit's)
RESERVED = ("pooled",)

#: What a data path should be, for the messages.
EXPECTED = "a regular CSV or Parquet file or a results folder"
#: the largest magnitude of a recorded signal: its squares and products with a parameter stay finite in float64
SIGNAL_LIMIT = 1e150


@dataclass(frozen=True)
class Behaviour:
    """One data set's episodes.

    Parameters
    ----------
    name : str
        Its label.
    contexts : array of int
        Each episode's context.
    decisions : array of int
        Each episode's decision.
    signals : dict of str to array of float
        Extra per-episode columns, by name.
    source : str
        The file it came from.
    free_choice : bool
        A decision is a context (the next one) rather than engage/disengage.
    seed : object
        The seed of the run that produced it (a results folder's runs), or None.
    ignored : tuple of str
        Numeric columns of its table that the fit does not read (neither required nor a replayed signal).
    """

    name: str
    contexts: np.ndarray
    decisions: np.ndarray
    signals: dict
    source: str
    free_choice: bool = False
    #: the seed of the run that produced it (a results folder's runs), or None
    seed: object = None
    #: numeric columns of its table that the fit does not read (neither required nor a replayed signal)
    ignored: tuple = ()

    def __len__(self) -> int:
        return len(self.contexts)

    def next_contexts(self, n_contexts: int) -> np.ndarray:
        """The context each decision led to: the next episode's; after the last episode, its own
        context on engage and the next one round on disengage (the run ends there, so no
        observation constrains it)."""
        nxt = np.empty_like(self.contexts)
        nxt[:-1] = self.contexts[1:]
        last, d = int(self.contexts[-1]), int(self.decisions[-1])
        nxt[-1] = d if self.free_choice else (last if d == 0 else (last + 1) % n_contexts)
        return nxt


def read_behaviour(path, context_names: Sequence[str], *, free_choice: bool = False,
                   signals: Sequence[str] = ()) -> list[Behaviour]:
    """The data sets of a CSV or Parquet file, or of a results folder (one per run), in order.

    Parameters
    ----------
    path : str or path
        A CSV or Parquet file, or a results folder.
    context_names : sequence of str
        The world's contexts (a context may be given by index or name).
    free_choice : bool
        Decisions are contexts rather than engage/disengage.
    signals : sequence of str
        The extra columns required (for signal replay).

    Returns
    -------
    list of Behaviour
        One per data set (per run of a results folder), in order.
    """
    path = Path(path)
    kind = path_kind(path, EXPECTED)
    if kind == "folder":
        store = ResultsStore(path)
        episodes, _ = store.load()
        table = pd.DataFrame({"dataset": episodes["condition"].astype(str) + "/" + episodes["run"].astype(str),
                              "episode": episodes["episode"], "context": episodes["context"],
                              "decision": episodes["next_context" if free_choice else "action"]})
        for name in signals:
            if name not in episodes:
                raise ConfigError(path, name, f"a recorded column '{name}' in the results folder", "none")
            table[name] = episodes[name]
    else:
        table = read_table(path, (".csv", *PARQUET_SUFFIXES), EXPECTED, header=", ".join(REQUIRED) + ", ...")
    found = behaviour_from_episodes(table, context_names, free_choice=free_choice, signals=signals, source=str(path))
    if kind == "folder":  # each run's own seed: its replay sees the run's own world
        seeds = {}
        for run_dir in store.run_dirs():
            seed = store.run_info(run_dir)["seed"]
            seeds[f"{run_dir.parent.name}/{int(run_dir.name.split('-')[1])}"] = np.random.SeedSequence(
                seed["entropy"], spawn_key=tuple(seed["spawn_key"]))
        found = [dataclasses.replace(b, seed=seeds.get(b.name)) for b in found]
    return found


def behaviour_from_episodes(table: pd.DataFrame, context_names: Sequence[str], *, free_choice: bool = False,
                            signals: Sequence[str] = (), source: str = "<table>") -> list[Behaviour]:
    """The data sets of a tidy table (columns :data:`REQUIRED` and ``signals``), checked.

    Parameters
    ----------
    table : pandas.DataFrame
        The tidy table, one row per episode.
    context_names : sequence of str
        The world's contexts.
    free_choice : bool
        Decisions are contexts rather than engage/disengage.
    signals : sequence of str
        The extra columns required (for signal replay).
    source : str
        The table's file, for the messages.

    Returns
    -------
    list of Behaviour
        One per ``dataset``.
    """
    for column in (*REQUIRED, *signals):
        if column not in table.columns:
            raise ConfigError(source, column, f"a column '{column}' (columns: {', '.join(map(str, table.columns))})",
                              "none")
        if table[column].isna().any():
            row = int(np.flatnonzero(table[column].isna().to_numpy())[0])
            raise ConfigError(source, column, "a value in every row", f"a missing value in row {row}")
    labels = table["dataset"].astype(str)
    for name in RESERVED:
        if (labels == name).any():
            row = int(np.flatnonzero((labels == name).to_numpy())[0])
            raise ConfigError(source, "dataset", f"data set names other than {', '.join(map(repr, RESERVED))} (the "
                              "outputs' name for the pooled fit)", f"{name!r} in row {row}")
    signal_values = {s: _finite(table[s], source, s) for s in signals}
    ignored = tuple(str(c) for c in table.columns if c not in REQUIRED and c not in signals
                    and pd.api.types.is_numeric_dtype(table[c].dtype) and not pd.api.types.is_bool_dtype(table[c].dtype))
    names = list(context_names)
    contexts = _codes(table["context"], names, source, "context", "a context index 0..{n} or name ({names})")
    if free_choice:
        decisions = _codes(table["decision"], names, source, "decision", "a chosen context 0..{n} or name ({names})")
    else:
        decisions = _codes(table["decision"], list(ACTIONS), source, "decision", "0, 1 or one of {names}")
    out = []
    frame = pd.DataFrame({"dataset": table["dataset"].astype(str).to_numpy(), "episode": table["episode"].to_numpy(),
                          "context": contexts, "decision": decisions})
    for name, rows in frame.groupby("dataset", sort=False).groups.items():
        rows = np.asarray(rows)
        episode = frame["episode"].to_numpy()[rows]
        if not np.issubdtype(episode.dtype, np.integer):
            raise ConfigError(source, "episode", "integer episode numbers", f"{episode.dtype} in data set '{name}'")
        if np.any(np.diff(episode) <= 0):
            k = int(np.flatnonzero(np.diff(episode) <= 0)[0]) + 1
            raise ConfigError(source, "episode", f"episodes in increasing order within data set '{name}'",
                              f"episode {episode[k]} after episode {episode[k - 1]}")
        c, d = frame["context"].to_numpy()[rows], frame["decision"].to_numpy()[rows]
        if free_choice and np.any(c[1:] != d[:-1]):
            k = int(np.flatnonzero(c[1:] != d[:-1])[0])
            raise ConfigError(source, "decision", f"in data set '{name}', the chosen context to be the next "
                              "episode's", f"context {d[k]} chosen at episode {episode[k]}, then context {c[k + 1]}")
        if not free_choice:
            moved = c[1:] != c[:-1]
            bad = np.flatnonzero(moved == (d[:-1] == 0))
            if len(bad):
                k = int(bad[0])
                said = ACTIONS[d[k]]
                raise ConfigError(source, "decision", f"in data set '{name}', 'engage' to stay in the context and "
                                  "'disengage' to leave it", f"'{said}' at episode {episode[k]} followed by "
                                  f"context {c[k + 1]} (from context {c[k]})")
        values = {s: v[rows] for s, v in signal_values.items()}
        out.append(Behaviour(str(name), c.astype(np.int64), d.astype(np.int64), values, source, free_choice,
                             ignored=ignored))
    if not out:
        raise ConfigError(source, "dataset", "at least one episode", "an empty table")
    return out


def _finite(column: pd.Series, source: str, key: str) -> np.ndarray:
    """A signal column as float64, refused (naming the row) unless every value is a number of magnitude at
    most :data:`SIGNAL_LIMIT` (an inf, or 1e308, makes the model's values inf - inf = NaN)."""
    values = pd.to_numeric(column, errors="coerce").to_numpy(dtype=np.float64)
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(values) <= SIGNAL_LIMIT)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise ConfigError(source, key, f"finite numbers of magnitude at most {SIGNAL_LIMIT:g}",
                          f"{column.iloc[row]!r} in row {row}")
    return values


def _codes(column: pd.Series, names: list[str], source: str, key: str, expected: str) -> np.ndarray:
    """Indices of ``column``'s values: integers in range, or names from ``names``."""
    n = len(names)
    expected = expected.format(n=n - 1, names=", ".join(names))
    values = column.to_numpy()
    if pd.api.types.is_numeric_dtype(column.dtype) and not pd.api.types.is_bool_dtype(column.dtype):
        codes = values.astype(np.int64)
        bad = (codes != values) | (codes < 0) | (codes >= n)
    else:
        lookup = {name: i for i, name in enumerate(names)}
        lookup.update({str(i): i for i in range(n)})
        codes = np.array([lookup.get(str(v), -1) for v in values], dtype=np.int64)
        bad = codes < 0
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise ConfigError(source, key, expected, f"{values[row]!r} in row {row}")
    return codes
