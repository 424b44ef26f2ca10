"""Degenerate conditions: a condition whose model cannot act in the experiment's world.

Run *i* of every condition has the same seed, hence the same world. A condition whose model
makes no difference in that world (a TD VTA, or an intrinsic/extrinsic mixture, in a world
without extrinsic reward: the TD error is 0 at every step, and the mixture is its intrinsic part)
then repeats another condition's runs exactly: the same contexts, the same decisions, the same
frames, the same stored modules, run for run. Compared with the reference it only repeats that
condition's test, and it would enlarge the multiple-comparison family for nothing; so the order
table and the summary report it as such and leave it out of their families by default
(:func:`~neurocur.analysis.stats.report.order_table`, :func:`~neurocur.analysis.stats.folder_summary.summary`).

Which of the identical conditions is kept: the reference (the experiment's first condition),
else the declared control (:attr:`~neurocur.analysis.results.Results.control`), else the first
in the experiment's order.
"""

from __future__ import annotations

import pandas as pd

from neurocur.analysis.results import Results

__all__ = ["BEHAVIOUR_COLUMNS", "degenerate_conditions"]

#: What a run did, compared between conditions: each episode's context, length and decision,
#: and each stored module's episode, source and gated contexts (those the tables have).
BEHAVIOUR_COLUMNS = {"episodes": ("run", "episode", "context", "n_frames", "action"),
                     "modules": ("run", "module", "episode", "source", "gates")}


def _behaviour(table: pd.DataFrame, condition: str, columns) -> pd.DataFrame:
    rows = table.loc[table["condition"] == condition, [c for c in columns if c in table]]
    return rows.sort_values(list(rows.columns[:2])).reset_index(drop=True)


def degenerate_conditions(results: Results) -> dict[str, str]:
    """Each condition whose runs repeat another's exactly (:data:`BEHAVIOUR_COLUMNS`, the same
    runs), mapped to the condition kept in its place (see the module docstring); empty when
    every condition behaved differently. Conditions of different worlds are never compared.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables (its episodes and modules) and the sources of each condition's world (``specs``).

    Returns
    -------
    dict of str to str
        ``{repeating condition: condition kept}``.
    """
    order = [c for c in results.specs if c in set(results.conditions)]
    order += [c for c in results.conditions if c not in order]
    first = [c for c in (results.reference, results.control) if c in order]
    order = [*first, *[c for c in order if c not in first]]
    kept: list[str] = []
    out: dict[str, str] = {}
    for condition in order:
        twin = next((k for k in kept if results.specs.get(k) == results.specs.get(condition)
                     and all(_behaviour(table, k, columns).equals(_behaviour(table, condition, columns))
                             for table, columns in ((results.episodes, BEHAVIOUR_COLUMNS["episodes"]),
                                                    (results.modules, BEHAVIOUR_COLUMNS["modules"])))), None)
        if twin is None:
            kept.append(condition)
        else:
            out[condition] = twin
    return out
