"""Experiments: a TOML spec → conditions × runs (paired seeds) → a results folder.

| part | module |
|---|---|
| the spec: validation, conditions, seeds; each condition's circuit and world parameters built once | ``spec`` |
| one run → tables (:class:`neurocur.results.RunResult`) | ``run`` |
| the local worker pool (schedules only) | ``pool`` |

The results folder belongs to :class:`neurocur.results.ResultsStore`.
"""

import importlib

__all__ = ["Condition", "Experiment", "load_experiment", "parse_set", "run_experiment", "run_one"]

#: where each name lives; imported on first use (PEP 562), so that ``neurocur.experiments.processes``
#: stays light and the command line can start the fork server before importing the model
_HOME = {"Condition": "spec", "Experiment": "spec", "load_experiment": "spec", "parse_set": "spec",
         "run_experiment": "pool", "run_one": "run"}


def __getattr__(name: str):
    if name in _HOME:
        return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *__all__})
