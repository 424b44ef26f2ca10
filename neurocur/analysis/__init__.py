"""Analysis of a results folder: tidy tables, statistics and seaborn figures.

``Results.load(DIR)`` (:mod:`~neurocur.analysis.results`) reads a folder's episodes and modules
tables (through :class:`neurocur.results.ResultsStore`), each condition's sources and its
``config.toml``; every statistic and figure that needs more than one table takes that
:class:`~neurocur.analysis.results.Results`. ``write_summary(DIR)`` writes ``summary.json``
(:mod:`~neurocur.analysis.io`), and ``dataset(DIR)`` a folder's run tables as one
:class:`pyarrow.dataset.Dataset` (``condition`` and ``run`` as columns) for pyarrow, duckdb or
polars, read through the store's checks; ``narrow(order_tables(DIR))`` the order table as
``neurocur run`` prints it, within 100 columns. Two rooms, every public name re-exported here:

:mod:`~neurocur.analysis.stats` — one module per question:

- :mod:`~neurocur.analysis.stats.order` — the module order per run, its counts (Clopper–Pearson
  intervals) and Kendall τ;
- :mod:`~neurocur.analysis.stats.learning_time` — the learning time of each source (Figure 4F);
- :mod:`~neurocur.analysis.stats.comparison` — one condition against another (paired by run), many
  against a reference, and the multiple-comparison adjustment;
- :mod:`~neurocur.analysis.stats.significance` — the two-sample tests (Wilcoxon signed-rank and
  McNemar exact, paired; Mann–Whitney U and Fisher exact, unpaired);
- :mod:`~neurocur.analysis.stats.bootstrap` — percentile bootstrap intervals over runs and pairs;
- :mod:`~neurocur.analysis.stats.sweeps` — every sweep point against a reference point, every
  condition against a reference condition at each point;
- :mod:`~neurocur.analysis.stats.report` — the order table beside the paper's numbers and its paired
  tests (``paired_tests``: the one computation of the adjusted p-values the table, the summary and
  the efficiency figure show);
- :mod:`~neurocur.analysis.stats.folder_summary` — the summary of a results folder, every statistic
  in one JSON-serialisable dict (``summary.json``);
- :mod:`~neurocur.analysis.stats.verdict` — per statistic, whether the reference differs from the
  control and whether the paper's number is reached (``verdict_text(DIR)``: as ``neurocur run``
  prints it under the order table);
- :mod:`~neurocur.analysis.stats.degenerate` — conditions whose runs repeat another's, left out of
  the comparisons;
- :mod:`~neurocur.analysis.stats.dwell` — visits, dwell per context, occupancy over time, the share
  of frames in chosen contexts after an event;
- :mod:`~neurocur.analysis.stats.efficiency` — frames until every learnable source is learned, frames
  in the unlearnable contexts, modules per 10⁵ frames, compared paired by run;
- :mod:`~neurocur.analysis.stats.inverted_u` — the two-lines test of an interior peak (Simonsohn
  2018), a quadratic fit beside it, the peak's location with a bootstrap interval;
- :mod:`~neurocur.analysis.stats.goldilocks` — engagement against learnability, the two-lines test
  per model;
- :mod:`~neurocur.analysis.stats.event_locked` — DA and NE averaged around events (module storage,
  context switches, familiarity onset) with intervals across runs; tonic against phasic NE;
- :mod:`~neurocur.analysis.stats.cycles` — the estimation error per learning cycle, aligned to module
  storage (Figure 4D), and the agent's behaviour in each cycle.
- :mod:`~neurocur.analysis.stats.choice_shares` — each option's share of a subject's free choices
  per bin of trials, the order in which the shares peak, tested against shuffles of the bins.

:mod:`~neurocur.analysis.figures` — matplotlib Figures (paper Figures 4D–G, the neuromodulator
and behaviour analyses, Goldilocks, iCub Figures 6–7, Figure 5), and the figure set of each
world type with ``write_all`` (every figure of a results folder as PNG files).

Not re-exported: :mod:`~neurocur.analysis.paper` (the paper's numbers, with their sections),
:mod:`~neurocur.analysis.stats.reproduction` (the reproduction study's table),
:mod:`~neurocur.analysis.stats.icub` (the iCub experiment's tables),
:mod:`~neurocur.analysis.stats.reward_model` (the value estimator's eq-14 model replayed from a
run's recorded DA and decisions) and :mod:`~neurocur.analysis.stats.keys` (the columns that
identify a run, contexts by index or by name: what the statistics' modules share).
"""

import ast
import functools
import importlib
from pathlib import Path

from neurocur.analysis.io import dataset as dataset
from neurocur.analysis.io import load as load
from neurocur.analysis.io import narrow as narrow
from neurocur.analysis.io import order_tables as order_tables
from neurocur.analysis.io import run_dirs as run_dirs
from neurocur.analysis.io import throughput as throughput
from neurocur.analysis.io import verdict_text as verdict_text
from neurocur.analysis.io import write_summary as write_summary
from neurocur.analysis.results import Results as Results
from neurocur.analysis.results import source_specs as source_specs
from neurocur.analysis.stats import (
    bootstrap,
    choice_shares,
    comparison,
    cycles,
    degenerate,
    dwell,
    efficiency,
    event_locked,
    folder_summary,
    learning_time,
    order,
    report,
    significance,
    sweeps,
    verdict,
)
from neurocur.analysis.stats.bootstrap import *  # noqa: F403
from neurocur.analysis.stats.choice_shares import *  # noqa: F403
from neurocur.analysis.stats.comparison import *  # noqa: F403
from neurocur.analysis.stats.cycles import *  # noqa: F403
from neurocur.analysis.stats.degenerate import *  # noqa: F403
from neurocur.analysis.stats.dwell import *  # noqa: F403
from neurocur.analysis.stats.efficiency import *  # noqa: F403
from neurocur.analysis.stats.event_locked import *  # noqa: F403
from neurocur.analysis.stats.folder_summary import *  # noqa: F403
from neurocur.analysis.stats.learning_time import *  # noqa: F403
from neurocur.analysis.stats.order import *  # noqa: F403
from neurocur.analysis.stats.report import *  # noqa: F403
from neurocur.analysis.stats.significance import *  # noqa: F403
from neurocur.analysis.stats.sweeps import *  # noqa: F403
from neurocur.analysis.stats.verdict import *  # noqa: F403
from neurocur.contexts.base import SourceSpec as SourceSpec
from neurocur.contexts.synthetic import SYNTHETIC as SYNTHETIC

_EAGER = ["dataset", "load", "narrow", "order_tables", "verdict_text", "run_dirs", "source_specs", "throughput", "write_summary", "Results", "SourceSpec",
          "SYNTHETIC", *order.__all__, *learning_time.__all__, *comparison.__all__, *significance.__all__,
          *bootstrap.__all__, *sweeps.__all__, *report.__all__, *folder_summary.__all__, *dwell.__all__, *efficiency.__all__,
          *event_locked.__all__, *cycles.__all__, *degenerate.__all__, *choice_shares.__all__, *verdict.__all__]

#: Re-exported, but imported on first use (PEP 562): they import matplotlib, seaborn or
#: statsmodels' full API (about 1.5 s), which loading results and writing a summary do not need.
#: The figures are the whole :mod:`~neurocur.analysis.figures` package (its ``__all__``).
_DEFERRED = ("figures", "stats.goldilocks", "stats.inverted_u")


def _deferred(name: str):
    return importlib.import_module(f"{__name__}.{name}")


def _all_of(path: Path) -> list[str]:
    """The public names of a module's source, read without importing it: its literal ``__all__``;
    for a package, the ``__all__`` of each module its ``__init__`` star-imports."""
    if path.is_dir():
        tree = ast.parse((path / "__init__.py").read_text(encoding="utf-8"))
        return [name for node in tree.body if isinstance(node, ast.ImportFrom) and node.level == 1
                and [a.name for a in node.names] == ["*"] for name in _all_of(path / f"{node.module}.py")]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    value = next(node.value for node in tree.body if isinstance(node, ast.Assign)
                 and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets))
    return ast.literal_eval(value)


@functools.cache
def _deferred_names() -> dict[str, str]:
    """Each deferred module's public name -> that module, read from its source without importing
    it, so that ``dir()`` (a notebook's tab completion) and a lookup of a name that is not there
    stay cheap."""
    here = Path(__file__).parent
    names = {}
    for sub in _DEFERRED:
        path = here.joinpath(*sub.split("."))
        names.update(dict.fromkeys(_all_of(path if path.is_dir() else path.with_suffix(".py")), sub))
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
