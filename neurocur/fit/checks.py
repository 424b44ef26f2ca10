"""What the fit commands check about their data before fitting: refusals and warnings.

- :func:`check_folder`: a results folder is fitted only under the experiment that wrote it. Its
  ``config.toml`` (:meth:`neurocur.results.ResultsStore.config`) names the experiment and, per
  condition, the world its runs saw and the circuit they ran; the replay builds the fitting
  condition's world with each run's seed, so another experiment, or a world that differs from the
  fitting condition's, would replay other frames and contexts (an estimate with no meaning). A
  condition of the folder that the experiment also has must have run the experiment's circuit.
- :func:`data_warnings`: what the fit would silently ignore: numeric columns of a table that it
  does not read (a signal column given without ``--signal`` is replaced by the circuit's own
  simulated signal), and contexts of the world that never occur in the data (the model still
  chooses among all of them, e.g. a 4-way softmax for 2-context data).
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path

from ..config import ConfigError
from ..results import ResultsStore, dumps_toml, first_difference
from ..results.fingerprint import portable

__all__ = ["check_folder", "data_warnings"]


def _as_recorded(tree: Mapping) -> dict:
    """``tree`` as a results folder's ``config.toml`` records it (TOML types, package paths portable)."""
    return portable(tomllib.loads(dumps_toml({"t": dict(tree)}))["t"])


def check_folder(path, experiment, conditions: Sequence) -> None:
    """ConfigError unless the results folder ``path`` (a table: nothing to check) was written by ``experiment``,
    the runs it holds saw the world of each of ``conditions`` (the fitting ones), and their conditions, where the
    experiment has them too, ran the experiment's circuit.

    Parameters
    ----------
    path : path
        The data: a results folder, or a table.
    experiment : Experiment
        The loaded experiment the fit uses.
    conditions : sequence of Condition
        The conditions fitted.
    """
    path = Path(path)
    if not path.is_dir() or path.is_symlink():
        return
    store = ResultsStore(path)
    config = store.config()
    if config is None:
        return  # the store refuses a folder with runs and no config.toml when it is read
    source = path / "config.toml"
    recorded = config.get("name")
    if recorded != experiment.name:
        raise ConfigError(source, "name", f"results of the experiment --experiment names ({experiment.name!r})",
                          f"{recorded!r}: the folder was written by another experiment; fit it with --experiment "
                          f"{recorded}")
    mine = experiment.resolved()["conditions"]
    ran = {run.parent.name for run in store.run_dirs()}  # the conditions whose runs are the data sets
    for name, folder in config.get("conditions", {}).items():
        if name not in ran:
            continue
        for condition in conditions:
            where = first_difference(folder.get("world"), _as_recorded(mine[condition.name]["world"]))
            if where is not None:
                raise ConfigError(source, f"conditions.{name}.world.{where}", f"the world of --experiment "
                                  f"{experiment.name}'s condition {condition.name!r} (its runs are replayed there)",
                                  "another world: the folder's runs saw other contexts or frames")
        if name in mine:
            where = first_difference(folder.get("resolved_circuit"), _as_recorded(mine[name]["resolved_circuit"]))
            if where is not None:
                raise ConfigError(source, f"conditions.{name}.resolved_circuit.{where}",
                                  f"the circuit of --experiment {experiment.name}'s condition {name!r}",
                                  "another circuit: the folder was written by another version of the experiment")


def data_warnings(data: Sequence, context_names: Sequence[str], source) -> dict:
    """``{"ignored_columns": [...], "unseen_contexts": [...], "lines": [...]}``: the table's numeric columns the fit
    does not read, the world's contexts no data set visits, and a warning line for each kind found.

    Parameters
    ----------
    data : sequence of Behaviour
        The data sets read.
    context_names : sequence of str
        The world's contexts.
    source : str or path
        The data's file, which each warning line names.

    Returns
    -------
    dict
        ``ignored_columns``, ``unseen_contexts`` and ``lines``.
    """
    ignored = sorted({c for b in data for c in getattr(b, "ignored", ())})
    seen = {int(c) for b in data for c in b.contexts}
    unseen = [name for i, name in enumerate(context_names) if i not in seen]
    lines = []
    if ignored:
        lines.append(f"{source}: the fit does not read the numeric column(s) {', '.join(map(repr, ignored))}; to "
                     "replay a recorded signal give --signal REGION=COLUMN (without it the circuit computes its own)")
    if unseen:
        lines.append(f"{source}: the world's context(s) {', '.join(map(repr, unseen))} never occur in the data, yet "
                     f"the model chooses among all {len(context_names)} contexts; is --experiment the data's?")
    return {"ignored_columns": ignored, "unseen_contexts": unseen, "lines": lines}
