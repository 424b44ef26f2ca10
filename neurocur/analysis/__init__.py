"""Analysis of a results folder: tidy tables, statistics and seaborn figures.

``load(DIR)`` reads the episodes and modules tables of every run; the functions of
:mod:`neurocur.analysis.stats` turn them into tidy statistics and those of
:mod:`neurocur.analysis.figures` into matplotlib Figures (paper Figures 4D–G);
:mod:`neurocur.analysis.icub` does the same for the iCub experiment (Figures 6B–D) and
:mod:`neurocur.analysis.invariance` draws Figure 5.
"""

from neurocur.analysis import figures, stats
from neurocur.analysis.figures import *  # noqa: F403
from neurocur.analysis.io import load, run_dirs
from neurocur.analysis.stats import *  # noqa: F403

__all__ = ["load", "run_dirs", *stats.__all__, *figures.__all__]
