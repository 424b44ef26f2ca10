"""Trial tables as experimenters record them: one row per trial, the option chosen and its outcome.

Columns (:data:`TRIAL_COLUMNS`, then any of :data:`OPTIONAL_COLUMNS` and further grouping columns):

- ``subject``: whose trials (any label); each subject is one data set;
- ``trial``: the trial's number, strictly increasing within a subject;
- ``choice``: the option chosen on that trial, a 0-based index or the option's name (the world's
  ``options``); 1-based integer codes only when the reader is told so (``one_based``, the
  command line's ``--one-based``), never guessed; an empty cell is a missed trial;
- ``outcome``: what the choice paid (a reward, or correct 0/1);
- ``rt`` (optional): the response time, kept per trial.

The model scores trial t's choice from trials before t and learns from trial t's outcome after it
(:mod:`neurocur.regions.bandit`), so no row is dropped: the first trial's choice is scored from
the initial values. A missed trial is skipped: no choice scored, no outcome learned, the
perseveration bonus goes to the last choice made; :attr:`Trials.skipped` counts them.

Files: CSV, Parquet and tab-separated text (``.csv``, ``.tsv``, ``.txt``: the delimiter is a tab
when the header line has one, else a comma). A column mapping (``columns``: standard name -> the
file's name, ``--columns choice=family,subject=sid``) reads other names. A results folder of an
experiment on the world of options is read as trials too (subject ``CONDITION/RUN``, trial the
episode, choice the context, outcome the reward). Bad data is one
:class:`~neurocur.config.ConfigError` naming the file and the file's column.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import ConfigError
from ..results import ResultsStore
from .files import PARQUET_SUFFIXES, path_kind, read_table

__all__ = ["OPTIONAL_COLUMNS", "TRIAL_COLUMNS", "Trials", "read_trials", "trials_from_episodes", "trials_from_table"]

#: The columns every trial table has (after the column mapping).
TRIAL_COLUMNS = ("subject", "trial", "choice", "outcome")
#: Standard columns a trial table may have.
OPTIONAL_COLUMNS = ("rt",)
#: Suffixes read as delimited text.
TEXT_SUFFIXES = (".csv", ".tsv", ".txt")

#: What a trial table's path should be, for the messages.
EXPECTED = "a regular trial table (.csv, .tsv, .txt, .parquet) or a results folder"


@dataclass(frozen=True)
class Trials:
    """One subject's trials that were made (a missed trial left out).

    Parameters
    ----------
    name : str
        The subject.
    choices : array of int
        Each trial's option index.
    outcomes : array of float
        Each trial's outcome.
    trials : array of int
        The trials' numbers as recorded.
    source : str
        The file.
    skipped : int
        The missed trials.
    signals : dict of str to array
        Optional per-trial columns, e.g. ``rt``.
    seed : object
        The seed its replay is given (the bandit circuit draws nothing once its choices are the observed ones).
    """

    name: str
    choices: np.ndarray
    outcomes: np.ndarray
    trials: np.ndarray
    source: str
    skipped: int = 0
    signals: dict = field(default_factory=dict)
    #: the seed its replay is given (the bandit circuit draws nothing once its choices are the observed ones)
    seed: object = None

    def __len__(self) -> int:
        return len(self.choices)

    @property
    def contexts(self) -> np.ndarray:
        """The options chosen: in the world of options, the context each trial visits."""
        return self.choices


def read_trials(path, option_names: Sequence[str], *, columns: Mapping[str, str] | None = None,
                one_based: bool = False) -> list[Trials]:
    """The subjects of a trial table (CSV, Parquet, tab-separated text) or of a results folder, in order.

    Parameters
    ----------
    path : str or Path
        A trial table (one row per trial: ``subject, trial, choice, outcome[, rt]``) or a results folder.
    option_names : sequence of str
        The world's options: a choice may be given by its index or its name.
    columns : mapping of str to str, optional
        Standard column -> the file's column (e.g. ``{"subject": "subjID"}``).
    one_based : bool
        Integer choice codes start at 1 (never guessed).

    Returns
    -------
    list of Trials
        One per subject, checked; a missed trial (empty choice) is kept and skipped by the likelihood.
    """
    path = Path(path)
    if path_kind(path, EXPECTED) == "folder":
        episodes, _ = ResultsStore(path).load()
        subjects = episodes["condition"].astype(str) + "/" + episodes["run"].astype(str)
        return trials_from_episodes(episodes, option_names, subjects, str(path))
    table = read_table(path, (*TEXT_SUFFIXES, *PARQUET_SUFFIXES), EXPECTED, header=", ".join(TRIAL_COLUMNS))
    return trials_from_table(rename(table, columns or {}, path), option_names, one_based=one_based, source=str(path),
                             origin=dict(columns or {}))


def trials_from_episodes(episodes: pd.DataFrame, option_names: Sequence[str], subject, source: str) -> list[Trials]:
    """The trials of a run's episodes table (a simulated agent on the world of options): each episode is a
    trial, its ``context`` the choice and its ``reward`` the outcome.

    Parameters
    ----------
    episodes : pandas.DataFrame
        The run's episodes table.
    option_names : sequence of str
        The world's options.
    subject : str or sequence of str
        A label, or one per row.
    source : str
        The data's origin, for the messages.

    Returns
    -------
    list of Trials
        One per subject.
    """
    table = pd.DataFrame({"subject": subject, "trial": episodes["episode"], "choice": episodes["context"],
                          "outcome": episodes["reward"]})
    return trials_from_table(table, option_names, source=source)


def rename(table: pd.DataFrame, columns: Mapping[str, str], source) -> pd.DataFrame:
    """``table`` with the file's columns renamed to the standard ones (``columns``: standard -> file's name)."""
    for standard, name in columns.items():
        if name not in table.columns:
            raise ConfigError(source, name, f"a column '{name}' for '{standard}' (--columns {standard}={name}; "
                              f"columns: {', '.join(map(str, table.columns))})", "none")
    return table.rename(columns={name: standard for standard, name in columns.items()})


def trials_from_table(table: pd.DataFrame, option_names: Sequence[str], *, one_based: bool = False,
                      source: str = "<table>", origin: Mapping[str, str] | None = None) -> list[Trials]:
    """The subjects of a table with the standard columns (:data:`TRIAL_COLUMNS`, then optional ones), checked.

    Parameters
    ----------
    table : DataFrame
        One row per trial, with the standard columns.
    option_names : sequence of str
        The world's options.
    one_based : bool
        Integer choice codes start at 1.
    source : str
        The file named in a message.
    origin : mapping of str to str, optional
        Standard column -> the file's name of it, named in a message.

    Returns
    -------
    list of Trials
        One per subject, in the table's order.
    """
    origin = dict(origin or {})

    def col(name: str) -> str:
        return origin.get(name, name)

    for name in TRIAL_COLUMNS:
        if name not in table.columns:
            raise ConfigError(source, col(name), f"a column '{name}' (columns: {', '.join(map(str, table.columns))}; "
                              f"map another name with --columns {name}=NAME)", "none")
    for name in ("subject", "trial"):
        if table[name].isna().any():
            row = int(np.flatnonzero(table[name].isna().to_numpy())[0])
            raise ConfigError(source, col(name), "a value in every row", f"a missing value in row {row}")
    missed = table["choice"].isna().to_numpy()
    choices = _choices(table["choice"], missed, list(option_names), one_based, source, col("choice"))
    outcomes = pd.to_numeric(table["outcome"], errors="coerce").to_numpy(dtype=np.float64)
    bad = ~missed & ~np.isfinite(outcomes)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise ConfigError(source, col("outcome"), "a number on every trial with a choice",
                          f"{_value(table['outcome'].to_numpy()[row])} in row {row}")
    trial = table["trial"].to_numpy()
    if not pd.api.types.is_integer_dtype(table["trial"].dtype):
        raise ConfigError(source, col("trial"), "integer trial numbers", f"{table['trial'].dtype}")
    signals = {name: pd.to_numeric(table[name], errors="coerce").to_numpy(dtype=np.float64)
               for name in OPTIONAL_COLUMNS if name in table.columns}
    out = []
    subjects = table["subject"].astype(str).to_numpy()
    for name, rows in pd.Series(np.arange(len(table))).groupby(subjects, sort=False).groups.items():
        rows = np.asarray(rows)
        t = trial[rows]
        if np.any(np.diff(t) <= 0):
            k = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
            raise ConfigError(source, col("trial"), f"trials in increasing order within subject '{name}'",
                              f"trial {t[k]} after trial {t[k - 1]}")
        made = rows[~missed[rows]]
        if not len(made):
            raise ConfigError(source, col("choice"), f"at least one choice of subject '{name}'", "only missed trials")
        out.append(Trials(str(name), choices[made], outcomes[made], trial[made], source, int(len(rows) - len(made)),
                          {s: v[made] for s, v in signals.items()}))
    if not out:
        raise ConfigError(source, col("subject"), "at least one trial", "an empty table")
    return out


def _choices(column: pd.Series, missed: np.ndarray, names: list[str], one_based: bool, source: str,
             key: str) -> np.ndarray:
    """Option indices of the choices (-1 on a missed trial): integer codes (0-based, or 1-based when
    ``one_based``) or option names; 1-based codes without ``one_based`` are refused, never guessed."""
    n = len(names)
    codes = np.full(len(column), -1, dtype=np.int64)
    values = column.to_numpy()[~missed]
    numeric = pd.api.types.is_numeric_dtype(column.dtype) and not pd.api.types.is_bool_dtype(column.dtype)
    if not numeric and len(values) and not pd.api.types.is_bool_dtype(column.dtype):  # codes read as text
        as_numbers = pd.to_numeric(pd.Series(values), errors="coerce")
        if as_numbers.notna().all():
            values, numeric = as_numbers.to_numpy(), True
    if numeric:
        ints = values.astype(np.int64)
        if np.any(ints != values):
            row = int(np.flatnonzero(~missed)[np.flatnonzero(ints != values)[0]])
            raise ConfigError(source, key, "integer option codes or option names", f"{_value(column.to_numpy()[row])} in row {row}")
        if one_based:
            ints = ints - 1
        elif len(ints) and ints.min() >= 1 and ints.max() == n:
            raise ConfigError(source, key, f"0-based option codes 0..{n - 1} (pass --one-based if codes start at 1)",
                              f"codes {ints.min()}..{ints.max()}")
        found = ints
        bad = (found < 0) | (found >= n)
        first = f"{1 if one_based else 0}..{n if one_based else n - 1}"
        expected = f"option codes {first} ({'1' if one_based else '0'}-based) or names ({', '.join(names)})"
    else:
        lookup = {name: i for i, name in enumerate(names)}
        found = np.array([lookup.get(str(v).strip(), -1) for v in values], dtype=np.int64)
        bad = found < 0
        expected = f"an option name ({', '.join(names)}) or an integer code"
    if bad.any():
        row = int(np.flatnonzero(~missed)[np.flatnonzero(bad)[0]])
        raise ConfigError(source, key, expected, f"{_value(column.to_numpy()[row])} in row {row}")
    codes[~missed] = found
    return codes


def _value(v) -> str:
    """A cell as a message shows it: its Python value's repr (``3``, ``1.5``, ``'C'``)."""
    return repr(v.item() if isinstance(v, np.generic) else v)
