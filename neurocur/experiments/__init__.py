"""Experiments: a TOML spec → conditions × runs (paired seeds) → a results folder.

| part | module |
|---|---|
| the spec: validation, conditions, seeds; each condition's circuit and world parameters built once | ``spec`` |
| one run → tables (:class:`neurocur.results.RunResult`) | ``run`` |
| the local worker pool (schedules only) | ``pool`` |

The results folder belongs to :class:`neurocur.results.ResultsStore`.
"""

from .pool import run_experiment
from .run import run_one
from .spec import Condition, Experiment, load_experiment, parse_set

__all__ = ["Condition", "Experiment", "load_experiment", "parse_set", "run_experiment", "run_one"]
