"""Analysis of a results folder: tidy tables, statistics and seaborn figures.

``load(DIR)`` reads the episodes and modules tables of every run; the functions of
:mod:`neurocur.analysis.stats` turn them into tidy statistics and those of
:mod:`neurocur.analysis.figures` into matplotlib Figures (paper Figures 4D–G).
"""

from neurocur.analysis.figures import (
    fig_cumulative_error,
    fig_intrinsic_reward,
    fig_learning_time,
    fig_neuromodulators,
    fig_order_counts,
    fig_reward_function,
    write_all,
)
from neurocur.analysis.io import load, run_dirs
from neurocur.analysis.stats import (
    SYNTHETIC,
    SourceSpec,
    clopper_pearson,
    compare,
    condition_summary,
    learning_time_summary,
    learning_times,
    order_counts,
    order_table,
    per_run,
    position_counts,
    summary,
)

__all__ = [
    "load",
    "run_dirs",
    "SourceSpec",
    "SYNTHETIC",
    "clopper_pearson",
    "per_run",
    "order_counts",
    "position_counts",
    "condition_summary",
    "learning_times",
    "learning_time_summary",
    "compare",
    "order_table",
    "summary",
    "fig_cumulative_error",
    "fig_intrinsic_reward",
    "fig_learning_time",
    "fig_reward_function",
    "fig_order_counts",
    "fig_neuromodulators",
    "write_all",
]
