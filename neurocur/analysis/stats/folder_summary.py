"""The summary of a results folder: every statistic of its conditions in one JSON-serialisable dict,
written as ``summary.json`` by :func:`~neurocur.analysis.io.write_summary`.

It gathers the statistics of :mod:`~neurocur.analysis.stats.order`,
:mod:`~neurocur.analysis.stats.learning_time`, :mod:`~neurocur.analysis.stats.efficiency`,
:mod:`~neurocur.analysis.stats.dwell` and :mod:`~neurocur.analysis.stats.comparison`, with the
efficiency tests of :func:`~neurocur.analysis.stats.report.paired_tests` (the ones the order table
and the efficiency figure show). Every p-value is named by its test (paired by run: Wilcoxon 1945
signed-rank, McNemar 1947 exact) and its multiple-comparison adjustment (Holm 1979 by default, or
Benjamini & Hochberg 1995).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from neurocur.analysis.results import Results

from .bootstrap import BOOTSTRAP_SEED, N_BOOT
from .comparison import ADJUSTMENT_NAMES, adjustment, compare_conditions
from .degenerate import degenerate_conditions
from .dwell import engagement_summary
from .efficiency import censoring_horizon, efficiency_per_run, efficiency_summary
from .learning_time import learning_time_summary, require_learning_columns
from .order import condition_summary, order_counts, per_run, require_order_columns
from .report import paired_tests
from .significance import TESTS

__all__ = ["summary"]


def _json_safe(value):
    """Plain Python values for json.dumps; NaN and ±inf become None."""
    if isinstance(value, Mapping):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    return value


def summary(
    results: Results,
    *,
    reference: str | None = None,
    exclude_degenerate: bool = True,
    paired: bool = True,
    adjust: str | None = "holm",
    n_boot: int = N_BOOT,
    seed: int = BOOTSTRAP_SEED,
) -> dict:
    """A JSON-serialisable summary of a results folder (written as ``summary.json``), its conditions
    sharing one world's sources; ``reference`` defaults to :attr:`~neurocur.analysis.results.Results.reference`.

    Keys: ``n_runs`` (per condition), ``order_counts``, ``metrics`` (mean/sd per condition),
    ``learning_time`` (epochs per learnable source), ``efficiency`` (per condition and metric:
    :func:`~neurocur.analysis.stats.efficiency.efficiency_summary`, the censored frames to learn all
    cut at ``horizon``, the shortest run; and ``comparisons``, ``reference``
    against every other condition on :data:`~neurocur.analysis.stats.efficiency.EFFICIENCY_TESTS`,
    adjusted as their own family), ``engagement`` (per condition and context: share of frames
    and mean dwell per visit, :func:`~neurocur.analysis.stats.dwell.engagement_summary`),
    ``comparisons`` (``reference`` against
    every other condition but the degenerate ones (unless ``exclude_degenerate`` is false), when both exist: :func:`~neurocur.analysis.stats.comparison.compare_conditions`,
    each row with its ``test``, raw ``p_value``, ``p_adjusted`` and ``adjustment``) and
    ``statistics`` (how the comparisons were made: pairing, the tests by ``method`` code
    with their references, the adjustment with its reference and family size, the
    bootstrap, and ``degenerate``: each condition left out of the comparisons because its runs repeat
    another's, :func:`~neurocur.analysis.stats.degenerate.degenerate_conditions`, with that other).
    NaN and infinities are written as null.

    Parameters
    ----------
    results : neurocur.analysis.results.Results
        A results folder's tables, its conditions sharing one world's sources.
    reference : str, optional
        The condition compared against the others; None: the experiment's reference.
    exclude_degenerate : bool
        Leave the conditions whose runs repeat another's out of the tests.
    paired : bool
        Pair the runs by ``run`` (the default) or test them as independent samples.
    adjust : str or None
        The adjustment of each family's p-values (``"holm"``, ``"bh"`` / ``"fdr_bh"``,
        ``"none"`` or None).
    n_boot : int
        The bootstrap resamples of each interval.
    seed : int
        The bootstrap's seed.

    Returns
    -------
    dict
        The keys above, with plain Python values.

    Raises
    ------
    ValueError
        When a column is missing or the conditions' worlds differ.
    """
    require_order_columns(results.episodes, results.modules, needed_by="summary")
    require_learning_columns(results.episodes, results.modules, needed_by="summary")
    reference = results.reference if reference is None else reference
    runs = per_run(results)
    conditions = sorted(runs["condition"].unique())
    efficiency = efficiency_per_run(results)
    comparisons = pd.DataFrame()
    degenerate = degenerate_conditions(results) if exclude_degenerate else {}
    others = [c for c in conditions if c != reference and c not in degenerate]
    if reference in conditions and others:
        comparisons = compare_conditions(runs, reference, others, paired=paired, adjust=adjust,
                                         n_boot=n_boot, seed=seed)
    efficiency_tests = paired_tests(results, reference, adjust=adjust, exclude_degenerate=exclude_degenerate,
                                    paired=paired, n_boot=n_boot, seed=seed)["efficiency"]
    adjusted = adjustment(adjust) or "none"
    methods = sorted(set(comparisons["method"])) if len(comparisons) else []
    result = {
        "n_runs": runs.groupby("condition").size().to_dict(),
        "order_counts": order_counts(results).to_dict("records"),
        "metrics": condition_summary(results).to_dict("records"),
        "learning_time": learning_time_summary(results).to_dict("records"),
        "efficiency": {"horizon": censoring_horizon(results),
                       "summary": efficiency_summary(efficiency, n_boot=n_boot, seed=seed).to_dict("records"),
                       "comparisons": efficiency_tests.to_dict("records")},
        "engagement": engagement_summary(results.episodes, results.spec, n_boot=n_boot, seed=seed).to_dict("records"),
        "comparisons": comparisons.to_dict("records"),
        "statistics": {
            "reference": reference if comparisons.size else None,
            "paired": paired, "pairing": "run" if paired else None,
            "tests": {m: {"name": TESTS[m][0], "reference": TESTS[m][1]} for m in methods},
            "adjustment": {"method": adjusted, "name": ADJUSTMENT_NAMES[adjusted][0],
                           "reference": ADJUSTMENT_NAMES[adjusted][1],
                           "n_tests": int(comparisons["n_tests"].iloc[0]) if len(comparisons) else 0},
            "bootstrap": {"interval": "percentile (Efron & Tibshirani 1993)", "n_boot": n_boot,
                          "confidence": 0.95, "seed": seed},
            "degenerate": degenerate,
        },
    }
    return _json_safe(result)
