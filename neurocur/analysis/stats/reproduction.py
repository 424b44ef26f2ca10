"""The reproduction study's main table (docs/reproduction.md), from a results folder.

One row per condition: the module-order counts (S-A first, S-B second, S-C third,
exact A→B→C, S-D stored), modules and gated learnable sources per run, Kendall τ
against the Ω order, then the curious-versus-random comparison on gated sources for
every condition that has a random-switching twin: the Wilcoxon signed-rank test
(Wilcoxon 1945) of the run-paired differences (run *i* of every condition has the same
seed, hence the same world; see :func:`~neurocur.analysis.stats.comparison.compare`), its
p-value raw and Holm-adjusted (Holm 1979) over the table's comparisons, and the
matched-pairs rank-biserial effect (+ when curiosity gates more). A condition's twin is
``<name>_random``; a condition that differs from another only in what the random LC
never reads (the reward, its model and the discount: ``HPC.reward_error``, ``VTA.*``,
``PFC.*``) shares that one's twin, by the paired seeds its runs are the same (see
:data:`SHARED_CONTROLS`). The paper's row (:data:`neurocur.analysis.paper.SYNTHETIC_CURIOUS`)
comes first.
"""

from __future__ import annotations

import math

import pandas as pd

from neurocur.analysis.paper import SYNTHETIC_CURIOUS
from neurocur.analysis.results import Results

from .comparison import adjust_pvalues, compare
from .order import per_run
from .report import order_table

__all__ = ["SHARED_CONTROLS", "COLUMNS", "study_table", "markdown"]

#: Conditions whose random-switching control is another condition's (see the module docstring).
SHARED_CONTROLS = {
    "reward_episode": "default_random", "alpha_005": "default_random", "alpha_05": "default_random",
    "discount_05": "default_random", "discount_099": "default_random", "no_boredom": "default_random",
    "norm_image": "chosen_random", "reward_episode_discount": "default_random",
}
_ORDER_ROWS = ("S-A first", "S-B second", "S-C third", "exact S-A→S-B→S-C", "S-D stored", "modules per run",
               "learnable sources gated", "Kendall τ vs Ω")
_P = "gated vs random: Wilcoxon signed-rank p (paired by run)"
_P_ADJUSTED, _EFFECT = "Holm-adjusted p", "effect (matched-pairs rank-biserial)"
#: The columns of :func:`study_table`: rows of the order table, then the comparison with the twin.
COLUMNS = [*_ORDER_ROWS, _P, _P_ADJUSTED, _EFFECT]


def study_table(results_dir) -> pd.DataFrame:
    """Conditions × :data:`COLUMNS` of the synthetic world, the paper's row first (cells are text).

    Parameters
    ----------
    results_dir : str or path
        The results folder of the reproduction study (synthetic world).

    Returns
    -------
    pandas.DataFrame
        Indexed by condition (``paper`` first), columns ``COLUMNS``; text cells, ``—`` where there
        is no value (no twin, or no p-value).
    """
    results = Results.load(results_dir)
    table = order_table(results).drop(columns=["paper", "paper (random)"]).T
    runs = per_run(results)
    conditions = list(table.index)
    tests = [compare(runs, a=name, b=twin, metric="gated_sources", adjust=None)
             for name in conditions if (twin := SHARED_CONTROLS.get(name, f"{name}_random")) in conditions]
    table = table.reindex(columns=COLUMNS).astype(object)
    if tests:
        for row in adjust_pvalues(pd.concat(tests, ignore_index=True), "holm").itertuples(index=False):
            if not math.isnan(row.p_value):
                table.loc[row.a, _P], table.loc[row.a, _P_ADJUSTED] = f"{row.p_value:.2g}", f"{row.p_adjusted:.2g}"
                table.loc[row.a, _EFFECT] = f"{row.effect_size:+.2f}"
    table = table.fillna("—")
    paper_row = {**{label: SYNTHETIC_CURIOUS[label].value for label in _ORDER_ROWS},
                 _P: "—", _P_ADJUSTED: "—", _EFFECT: "—"}
    return pd.concat([pd.DataFrame([paper_row], index=["paper"]), table])


def markdown(table: pd.DataFrame) -> str:
    """``table`` as a GitHub Markdown table (index as the first column).

    Parameters
    ----------
    table : pandas.DataFrame
        A table such as ``study_table``'s.

    Returns
    -------
    str
        The table's lines, without a trailing newline.
    """
    head = ["condition", *table.columns]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join([str(i), *map(str, row)]) + " |" for i, row in zip(table.index, table.values)]
    return "\n".join(lines)
