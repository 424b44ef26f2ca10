"""Analysis of a results folder: tidy tables, statistics and seaborn figures.

``load(DIR)`` reads the episodes and modules tables of every run (through
:class:`neurocur.results.ResultsStore`), and ``write_summary(DIR)`` writes ``summary.json``.
One module per question, all re-exported here:

- :mod:`~neurocur.analysis.order` — the module order per run, its counts (Clopper–Pearson
  intervals) and Kendall τ;
- :mod:`~neurocur.analysis.learning_time` — the learning time of each source (Figure 4F);
- :mod:`~neurocur.analysis.comparison` — one condition against another (paired by run), many
  against a reference, and the multiple-comparison adjustment;
- :mod:`~neurocur.analysis.significance` — the two-sample tests (Wilcoxon signed-rank and
  McNemar exact, paired; Mann–Whitney U and Fisher exact, unpaired);
- :mod:`~neurocur.analysis.bootstrap` — percentile bootstrap intervals over runs and pairs;
- :mod:`~neurocur.analysis.sweeps` — every sweep point against a reference point, every
  condition against a reference condition at each point;
- :mod:`~neurocur.analysis.report` — the order table beside the paper's numbers, and the summary;
- :mod:`~neurocur.analysis.dwell` — visits, dwell per context, occupancy over time, the share
  of frames in chosen contexts after an event;
- :mod:`~neurocur.analysis.efficiency` — frames until every learnable source is learned, frames in
  the unlearnable contexts, modules per 10⁵ frames, compared paired by run;
- :mod:`~neurocur.analysis.inverted_u` — the two-lines test of an interior peak (Simonsohn 2018),
  a quadratic fit beside it, the peak's location with a bootstrap interval;
- :mod:`~neurocur.analysis.goldilocks` — engagement against learnability, the two-lines test per
  model, its figure;
- :mod:`~neurocur.analysis.event_locked` — DA and NE averaged around events (module storage,
  context switches, familiarity onset) with intervals across runs; tonic against phasic NE;
- :mod:`~neurocur.analysis.cycles` — the estimation error per learning cycle, aligned to module
  storage (Figure 4D), and the agent's behaviour in each cycle;
- :mod:`~neurocur.analysis.figures` — matplotlib Figures (paper Figures 4D–G);
- :mod:`~neurocur.analysis.write` — every figure of a results folder as PNG files (``write_all``);
- :mod:`~neurocur.analysis.figures_neuro` — the figures of the neuromodulator and behaviour
  analyses (inverted U, occupancy, signals over time, event-locked traces, efficiency).

Not re-exported: :mod:`~neurocur.analysis.paper` (the paper's numbers, with their sections),
:mod:`~neurocur.analysis.style` (the figure style and saving),
:mod:`~neurocur.analysis.reproduction` (the reproduction study's table),
:mod:`~neurocur.analysis.icub` (the iCub experiment, Figures 6B–D and 7),
:mod:`~neurocur.analysis.invariance` (Figure 5) and :mod:`~neurocur.analysis.reward_model` (the
PFC's eq-14 model replayed from a run's recorded DA and decisions).
"""

import ast
import functools
import importlib
from pathlib import Path

from neurocur.analysis import (
    bootstrap,
    comparison,
    cycles,
    dwell,
    efficiency,
    event_locked,
    learning_time,
    order,
    report,
    significance,
    sweeps,
)
from neurocur.analysis.bootstrap import *  # noqa: F403
from neurocur.analysis.comparison import *  # noqa: F403
from neurocur.analysis.cycles import *  # noqa: F403
from neurocur.analysis.dwell import *  # noqa: F403
from neurocur.analysis.efficiency import *  # noqa: F403
from neurocur.analysis.event_locked import *  # noqa: F403
from neurocur.analysis.io import load as load
from neurocur.analysis.io import order_tables as order_tables
from neurocur.analysis.io import run_dirs as run_dirs
from neurocur.analysis.io import source_specs as source_specs
from neurocur.analysis.io import throughput as throughput
from neurocur.analysis.io import write_summary as write_summary
from neurocur.analysis.learning_time import *  # noqa: F403
from neurocur.analysis.order import *  # noqa: F403
from neurocur.analysis.report import *  # noqa: F403
from neurocur.analysis.significance import *  # noqa: F403
from neurocur.analysis.sweeps import *  # noqa: F403
from neurocur.contexts.base import SourceSpec as SourceSpec
from neurocur.contexts.synthetic import SYNTHETIC as SYNTHETIC

_EAGER = ["load", "order_tables", "run_dirs", "source_specs", "throughput", "write_summary", "SourceSpec", "SYNTHETIC",
          *order.__all__, *learning_time.__all__, *comparison.__all__, *significance.__all__, *bootstrap.__all__,
          *sweeps.__all__, *report.__all__, *dwell.__all__, *efficiency.__all__, *event_locked.__all__,
          *cycles.__all__]

#: Re-exported, but imported on first use (PEP 562): they import matplotlib, seaborn or
#: statsmodels' full API (about 1.5 s), which loading results and writing a summary do not need.
_DEFERRED = ("figures", "figures_neuro", "goldilocks", "inverted_u", "write")


def _deferred(name: str):
    return importlib.import_module(f"{__name__}.{name}")


@functools.cache
def _deferred_names() -> dict[str, str]:
    """Each deferred module's public name -> that module, read from the literal ``__all__`` of its
    source without importing it, so that ``dir()`` (a notebook's tab completion) and a lookup of a
    name that is not there stay cheap."""
    names = {}
    for sub in _DEFERRED:
        tree = ast.parse(Path(__file__).with_name(f"{sub}.py").read_text(encoding="utf-8"))
        value = next(node.value for node in tree.body if isinstance(node, ast.Assign)
                     and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets))
        names.update(dict.fromkeys(ast.literal_eval(value), sub))
    return names


def __getattr__(name: str):
    if name == "__all__":  # a star import asks for it, then fetches every name: the deferred modules load then
        return [*_EAGER, *_deferred_names()]
    if name in _DEFERRED:
        return _deferred(name)
    if name in _deferred_names():
        return getattr(_deferred(_deferred_names()[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *_EAGER, *_deferred_names(), *_DEFERRED})
