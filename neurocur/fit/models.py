"""What ``neurocur fit`` needs of a model beyond the replay: its free parameters and the kind of data it reads.

- **Free parameters.** A condition of an experiment file may declare the keys it fits
  (``fit = ["PFC.alpha", "LC.beta"]`` in ``[conditions.NAME]``); :func:`fit_keys` gives them when
  the command line names none (``--fit``), :func:`model_keys` each compared model's own, and their
  declared domains are the default bounds (:func:`neurocur.fit.study.default_bounds`).
- **Which data.** The experiment decides: an experiment whose world replays recorded trials
  (the world of options, :class:`~neurocur.contexts.options.OptionsWorld`: the bandit) reads trial
  tables and its own results folders as trials (:mod:`neurocur.fit.trials`); every other
  experiment reads episode tables and results folders as before (:mod:`neurocur.fit.data`).
  ``--columns`` and ``--one-based`` describe a trial table, so they are refused for the others.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..config import ConfigError
from .trials import OPTIONAL_COLUMNS, TRIAL_COLUMNS, Trials, read_trials

__all__ = ["data_summary", "fit_keys", "load_fit_data", "model_keys", "parse_columns", "reads_trials"]


def parse_columns(items: Sequence[str]) -> dict[str, str]:
    """``["choice=family,outcome=correct", "subject=sid"]`` -> ``{"choice": "family", ...}`` (standard -> file's).

    Parameters
    ----------
    items : sequence of str
        The ``--columns`` values, ``KEY=NAME`` pairs separated by commas.

    Returns
    -------
    dict of str to str
        The file's column of each standard one.
    """
    out: dict[str, str] = {}
    known = (*TRIAL_COLUMNS, *OPTIONAL_COLUMNS)
    for item in (part for text in items for part in text.split(",") if part.strip()):
        key, sep, name = (s.strip() for s in item.partition("="))
        if not sep or not name or key not in known:
            raise ConfigError("--columns", key or item, f"KEY=NAME with KEY one of {', '.join(known)}", repr(item))
        if key in out:
            raise ConfigError("--columns", key, "each column mapped once", f"{out[key]!r} and {name!r}")
        out[key] = name
    return out


def fit_keys(condition, given: Sequence[str]) -> list[str]:
    """The ``--fit`` keys, else the condition's declared free parameters (its ``fit`` list).

    Parameters
    ----------
    condition : Condition
        The experiment condition fitted.
    given : sequence of str
        The ``--fit`` keys (may be empty).

    Returns
    -------
    list of str
        The keys fitted.
    """
    keys = list(given) or list(getattr(condition, "fit", ()))
    if not keys:
        raise ConfigError("--fit", None, "--fit REGION.param (the condition declares no free parameters: fit = [...] "
                          f"in its experiment file's [conditions.{condition.name}])", "none")
    return keys


def model_keys(experiment, names: Sequence[str], given: Sequence[str]) -> list[str]:
    """The ``--fit`` keys of a model comparison, else each model's declared free parameters as
    ``MODEL:REGION.param`` (each fitted in its own model only, :func:`neurocur.fit.study.model_bounds`).

    Parameters
    ----------
    experiment : Experiment or str
        The experiment (as :func:`neurocur.fit.study.condition_of` takes it).
    names : sequence of str
        The conditions compared as models.
    given : sequence of str
        The ``--fit`` keys (may be empty).

    Returns
    -------
    list of str
        The keys fitted.
    """
    if given:
        return list(given)
    return [f"{name}:{key}" for name in names if name in experiment.conditions
            for key in experiment.conditions[name].fit]


def reads_trials(condition) -> bool:
    """True when the condition's world replays recorded trials (module docstring).

    Parameters
    ----------
    condition : Condition
        The experiment condition.
    """
    return hasattr(condition.world_class, "recorded")


def load_fit_data(data, condition, *, columns: Sequence[str] = (), one_based: bool = False, decision: str = "LC",
                  signal: tuple[str, str] | None = None) -> list:
    """The data sets of ``data`` for the condition's model: :class:`~neurocur.fit.trials.Trials` per subject
    for an experiment on trials, else the episode data sets of :func:`neurocur.fit.study.load_data`.

    Parameters
    ----------
    data : str or path
        A table or a results folder.
    condition : Condition
        The experiment condition fitted.
    columns : sequence of str
        The ``--columns`` mapping of a trial table (:func:`parse_columns`); refused for episode data.
    one_based : bool
        A trial table's integer choice codes start at 1; refused for episode data.
    decision : str
        The region whose decisions are the data.
    signal : (str, str), optional
        (region, column): signal replay.

    Returns
    -------
    list of Trials or list of Behaviour
        One per subject or data set, in order.
    """
    mapping = parse_columns(columns)
    if reads_trials(condition):
        return read_trials(data, condition.make_world().context_names, columns=mapping, one_based=one_based)
    if mapping or one_based:
        flag = "--columns" if mapping else "--one-based"
        raise ConfigError(flag, None, "an experiment on trials (world type 'options', e.g. --experiment bandit); "
                          "this experiment reads episode tables (dataset, episode, context, decision)",
                          f"world type '{condition.world_type}'")
    from .study import load_data

    return load_data(data, condition, decision=decision, signal=signal)


def data_summary(data: Sequence, *, columns: Sequence[str] = (), one_based: bool = False) -> dict:
    """What summary.json records of a trial table's reading: the column mapping, ``one_based`` and the
    missed trials skipped (per subject and in all); nothing for episode data.

    Parameters
    ----------
    data : sequence of Trials or Behaviour
        The data sets read (:func:`load_fit_data`).
    columns : sequence of str
        The ``--columns`` given.
    one_based : bool
        The ``--one-based`` given.

    Returns
    -------
    dict
        ``columns``, ``one_based`` and the skipped trials; empty for episode data.
    """
    if not data or not isinstance(data[0], Trials):
        return {}
    return {"columns": parse_columns(columns), "one_based": bool(one_based),
            "skipped": sum(d.skipped for d in data), "skipped_by_subject": {d.name: d.skipped for d in data}}
