"""Analysis of a results folder: tidy tables, statistics and seaborn figures.

``load(DIR)`` reads the episodes and modules tables of every run (through
:class:`neurocur.results.ResultsStore`), and ``write_summary(DIR)`` writes ``summary.json``; the functions of
:mod:`neurocur.analysis.stats` turn them into tidy statistics and those of
:mod:`neurocur.analysis.figures` into matplotlib Figures (paper Figures 4D–G);
:mod:`neurocur.analysis.icub` does the same for the iCub experiment (Figures 6B–D) and
:mod:`neurocur.analysis.invariance` draws Figure 5.
"""

from neurocur.analysis import figures, stats
from neurocur.analysis.figures import *  # noqa: F403
from neurocur.analysis.io import load, order_tables, run_dirs, source_specs, write_summary
from neurocur.analysis.stats import *  # noqa: F403

__all__ = ["load", "order_tables", "run_dirs", "source_specs", "write_summary", *stats.__all__, *figures.__all__]
