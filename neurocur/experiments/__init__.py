"""Experiments: a TOML spec → conditions × runs (paired seeds) → a results folder.

| part | module |
|---|---|
| the entrance, :func:`load_experiment`: resolve → expand → build, each pass entered once | ``spec`` |
| 1. resolve: the file, its ``extends`` chain, its circuit files (each read once) and ``--set`` → one table that remembers where each value came from | ``resolve``, ``resolved`` |
| 2. expand: conditions × sweep points (pure) | ``expand`` |
| 3. build: each condition's circuit and world parameters, once | ``build`` |
| what the entrance makes: :class:`Condition`, :class:`Experiment` (seeds of the runs) | ``conditions`` |
| one run → tables (:class:`neurocur.results.RunResult`) | ``run`` |
| the runner, :func:`run_experiment`: the folder's lock, the seed of an experiment without one, pre-flight checks; calls an executor | ``runner`` |
| executors: the protocol, and the one of ``--scheduler`` and ``--jobs`` | ``executors`` |
| the local worker pool (the one owner of the fork server), a Dask cluster | ``pool``, ``cluster`` |

The results folder belongs to :class:`neurocur.results.ResultsStore`.
"""

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # what the names are, for type checkers and the API docs; imported on first use below
    from .conditions import Condition, Experiment
    from .resolve import parse_set
    from .run import run_one
    from .runner import run_experiment
    from .spec import load_experiment

__all__ = ["Condition", "Experiment", "load_experiment", "parse_set", "run_experiment", "run_one"]

#: where each name lives; imported on first use (PEP 562), so that ``neurocur.experiments.processes``
#: stays light and the command line can start the fork server before importing the model
_HOME = {"Condition": "conditions", "Experiment": "conditions", "load_experiment": "spec", "parse_set": "resolve",
         "run_experiment": "runner", "run_one": "run"}


def __getattr__(name: str):
    if name in _HOME:
        return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *__all__})
