"""The reproduction study's main table (docs/reproduction.md), from a results folder.

One row per condition: the module-order counts (S-A first, S-B second, S-C third,
exact A→B→C, S-D stored), modules and gated learnable sources per run, Kendall τ
against the Ω order, then the curious-versus-random comparison on gated sources for
every condition that has a random-switching twin: Mann–Whitney U p-value and
rank-biserial effect size. A condition's twin is ``<name>_random``; a condition that
differs from another only in what the random LC never reads (the reward, its model and
the discount: ``HPC.reward_error``, ``VTA.*``, ``PFC.*``) shares that one's twin, by
the paired seeds its runs are the same (see :data:`SHARED_CONTROLS`). The paper's row
(:data:`neurocur.analysis.paper.SYNTHETIC_CURIOUS`) comes first.
"""

from __future__ import annotations

import pandas as pd

from neurocur.results import load

from .comparison import compare
from .order import per_run
from .paper import SYNTHETIC_CURIOUS
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
_P, _EFFECT = "gated vs random: p", "effect (rank-biserial)"
#: The columns of :func:`study_table`: rows of the order table, then the comparison with the twin.
COLUMNS = [*_ORDER_ROWS, _P, _EFFECT]


def study_table(results_dir) -> pd.DataFrame:
    """Conditions × :data:`COLUMNS` of the synthetic world, the paper's row first (cells are text)."""
    episodes, modules = load(results_dir)
    table = order_table(episodes, modules).drop(columns=["paper", "paper (random)"]).T
    runs = per_run(episodes, modules)
    conditions = list(table.index)
    for name in conditions:
        twin = SHARED_CONTROLS.get(name, f"{name}_random")
        if twin in conditions:
            row = compare(runs, a=name, b=twin, metric="gated_sources").iloc[0]
            table.loc[name, _P] = f"{row.p_value:.2g}"
            table.loc[name, _EFFECT] = f"{row.effect_size:+.2f}"
    table = table.reindex(columns=COLUMNS).astype(object).fillna("—")
    paper_row = {**{label: SYNTHETIC_CURIOUS[label].value for label in _ORDER_ROWS}, _P: "—", _EFFECT: "—"}
    return pd.concat([pd.DataFrame([paper_row], index=["paper"]), table])


def markdown(table: pd.DataFrame) -> str:
    """``table`` as a GitHub Markdown table (index as the first column)."""
    head = ["condition", *table.columns]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join([str(i), *map(str, row)]) + " |" for i, row in zip(table.index, table.values)]
    return "\n".join(lines)
