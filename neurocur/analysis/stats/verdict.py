"""The verdict of a results folder, per statistic: does the reference condition differ from the
control, and does it reach the paper's number?

:func:`verdict_table` sets, for each statistic of the order table (the module-order outcomes, the
modules per run, the sources gated, Kendall τ and the learning time per source), the reference
condition (the curious agent) beside the control (random switching, section 4.3) and the paper's
number (Luciw et al. 2013, :mod:`~neurocur.analysis.paper`), and says in two words:

- **differs?** — "yes" when the paired test of the reference against the control (McNemar 1947
  exact for a yes/no outcome, Wilcoxon 1945 signed-rank for a number; paired by run,
  :func:`~neurocur.analysis.stats.comparison.compare`) has a p-value below ``alpha`` after Holm's
  (1979) adjustment over every test of the table; else "no";
- **paper within CI?** — "yes" when the paper's number lies inside the 95 % interval of the
  reference's observed value: for a count ("18/25") the paper's proportion inside the
  Clopper–Pearson interval of the observed k/n (:func:`~neurocur.analysis.stats.order.clopper_pearson`),
  for a number the paper's value (or range, "2–3": overlapping it) inside the percentile
  bootstrap interval of the mean over runs (:func:`~neurocur.analysis.stats.bootstrap.bootstrap_ci`).

:func:`verdict_notes` states those rules, the smallest p-value the runs allow, and what each
condition is (its ``description`` in the folder's ``config.toml``), one line each.
"""

from __future__ import annotations

import math
import re

import pandas as pd

from neurocur.analysis import paper
from neurocur.analysis.results import Results

from .bootstrap import BOOTSTRAP_SEED, N_BOOT, bootstrap_ci
from .comparison import compare
from .learning_time import learning_times
from .order import BINARY_METRICS, clopper_pearson, ordinal_columns, outcome_labels, per_run
from .significance import TESTS

__all__ = ["VERDICT_METRICS", "paper_range", "count_reached", "mean_reached", "differs", "verdict_table",
           "fewest_runs", "verdict_notes"]

#: The numeric per-run metrics the verdict tests, with the order table's row label of each.
VERDICT_METRICS = {"n_modules": "modules per run", "gated_sources": "learnable sources gated",
                   "kendall_tau": "Kendall τ vs Ω"}
_SHORT_TEST = {"wilcoxon": "Wilcoxon", "mcnemar_exact": "McNemar"}


def paper_range(value: str) -> tuple[float, float, int | None]:
    """A number of the paper as ``(low, high, n)``: a count "18/25" as its proportion (0.72, 0.72, 25),
    a range "2–3" as (2, 3, None), "≈15" or "0.81" as a point (n None).

    Parameters
    ----------
    value : str
        The number as the paper's table states it: "k/n", "low–high", or a point, optionally after "≈".

    Returns
    -------
    tuple
        ``(low, high, n)``, ``n`` the count's denominator or None.
    """
    text = value.strip().lstrip("≈~").strip()
    if m := re.fullmatch(r"(\d+)\s*/\s*(\d+)", text):
        k, n = int(m[1]), int(m[2])
        return k / n, k / n, n
    if m := re.fullmatch(r"([-\d.]+)\s*[–-]\s*([-\d.]+)", text):
        return float(m[1]), float(m[2]), None
    return float(text), float(text), None


def count_reached(k: int, n: int, paper_share: float, confidence: float = 0.95) -> bool | None:
    """Whether the paper's proportion ``paper_share`` lies inside the Clopper–Pearson ``confidence``
    interval of ``k`` out of ``n``; None when there are no runs.

    Parameters
    ----------
    k : int
        Runs with the outcome.
    n : int
        Runs in all.
    paper_share : float
        The paper's proportion, in [0, 1].
    confidence : float
        Coverage of the Clopper–Pearson interval.
    """
    low, high = clopper_pearson(k, n, confidence)
    return None if math.isnan(low) else bool(low - 1e-12 <= paper_share <= high + 1e-12)


def mean_reached(values, low: float, high: float, *, confidence: float = 0.95, n_boot: int = N_BOOT,
                 seed: int = BOOTSTRAP_SEED) -> bool | None:
    """Whether the percentile bootstrap ``confidence`` interval of the mean of ``values`` meets the
    paper's ``[low, high]``; None when no value is finite.

    Parameters
    ----------
    values : array_like
        One value per run; NaN values are dropped.
    low, high : float
        The paper's range (equal for a point).
    confidence : float
        Coverage of the bootstrap interval.
    n_boot : int
        Number of resamples.
    seed : int
        Seed of the resamples.
    """
    ci_low, ci_high = bootstrap_ci(values, n_boot=n_boot, confidence=confidence, seed=seed)
    return None if math.isnan(ci_low) else bool(ci_low <= high and low <= ci_high)


def differs(p_adjusted: float, alpha: float = 0.05) -> bool | None:
    """Whether an adjusted p-value is below ``alpha``; None when nothing could be tested (NaN).

    Parameters
    ----------
    p_adjusted : float
        The adjusted p-value, NaN (or None) when nothing was tested.
    alpha : float
        The significance level.
    """
    return None if p_adjusted is None or math.isnan(p_adjusted) else bool(p_adjusted < alpha)


def _word(answer: bool | None) -> str:
    return "—" if answer is None else ("yes" if answer else "no")


def _mean_sd(values: pd.Series) -> str:
    values = values.dropna()
    if not len(values):
        return "—"
    return f"{values.mean():.2f}" if len(values) < 2 else f"{values.mean():.2f} ± {values.std():.2f}"


def _test_column(reference: str, control: str, n_pairs: int, n_tests: int) -> str:
    return f"{reference} vs {control}: p (n = {n_pairs} paired runs; Holm over {n_tests} tests)"


def verdict_table(results: Results, reference: str, control: str, *, alpha: float = 0.05,
                  confidence: float = 0.95, with_paper: bool = True, n_boot: int = N_BOOT,
                  seed: int = BOOTSTRAP_SEED) -> pd.DataFrame:
    """One row per statistic (indexed "outcome", the order table's labels): "paper" (the paper's
    number, :data:`~neurocur.analysis.paper.SYNTHETIC_CURIOUS`, when ``with_paper``), the
    observed value of ``reference`` and of ``control`` ("k/n" or mean ± sd), the test column
    (the Holm-adjusted p-value of the paired test, named in the cell: "0.062 (McNemar)"), "differs?"
    (:func:`differs` at ``alpha``) and "paper within CI?" (:func:`count_reached` or
    :func:`mean_reached` at ``confidence``; "—" without a paper number). The learning times are
    not tested ("—": a run has one only for a source it learned). ``attrs["n_tests"]``: the size of
    the Holm family.

    Parameters
    ----------
    results : Results
        The results folder, holding both conditions.
    reference : str
        The condition compared (the paper's agent), whose values meet the paper's numbers.
    control : str
        The condition it is tested against, paired by run.
    alpha : float
        The level of "differs?".
    confidence : float
        Coverage of the intervals of "paper within CI?".
    with_paper : bool
        Whether to add the paper's column and check its numbers.
    n_boot : int
        Resamples of the bootstrap intervals.
    seed : int
        Seed of the bootstrap resamples.

    Returns
    -------
    pandas.DataFrame
        The table described above.
    """
    for name in (reference, control):
        if name not in results.conditions:
            raise ValueError(f"verdict_table: condition {name!r} not in the results; have {results.conditions}")
    spec = results.spec_of(reference)
    runs = per_run(results.select([reference, control]))
    labels = {**outcome_labels(spec), **VERDICT_METRICS}
    metrics = [m for m in [*ordinal_columns(runs), *BINARY_METRICS, *VERDICT_METRICS] if m in labels]
    tests = compare(runs, reference, control, metrics, paired=True, adjust="holm", n_boot=n_boot, seed=seed)
    n_pairs = int(tests["n_pairs"].max()) if len(tests) else 0
    n_tests = int(tests["n_tests"].iloc[0]) if len(tests) else 0
    test_column = _test_column(reference, control, n_pairs, n_tests)
    numbers = paper.SYNTHETIC_CURIOUS if with_paper else {}
    ref_runs = runs[runs["condition"] == reference]
    rows = {}
    for test in tests.itertuples(index=False):
        label = labels[test.metric]
        cells = {}
        for name in (reference, control):
            values = runs.loc[runs["condition"] == name, test.metric]
            cells[name] = (f"{int(values.sum())}/{len(values)}" if values.dtype == bool
                           else _mean_sd(values.astype(float)))
        p = test.p_adjusted
        cells[test_column] = "—" if math.isnan(p) else f"{p:.2g} ({_SHORT_TEST.get(test.method, test.method)})"
        cells["differs?"] = _word(differs(p, alpha))
        cells["paper within CI?"] = _word(_reached(numbers.get(label), ref_runs[test.metric], confidence, n_boot, seed))
        rows[label] = cells
    times = learning_times(results.select([reference, control]))
    times = times[times["learnable"] & times["first_of_source"]]
    for source in spec.learnable:
        label = f"{source} learning time (epochs)"
        cells = {name: _mean_sd(times.loc[(times["condition"] == name) & (times["source"] == source), "epochs"])
                 for name in (reference, control)}
        mine = times.loc[(times["condition"] == reference) & (times["source"] == source), "epochs"]
        cells.update({test_column: "—", "differs?": "—",
                      "paper within CI?": _word(_reached(numbers.get(label), mine, confidence, n_boot, seed))})
        rows[label] = cells
    table = pd.DataFrame.from_dict(rows, orient="index").rename_axis("outcome")
    if with_paper:
        table.insert(0, "paper", [numbers[label].cell() if label in numbers else "—" for label in table.index])
    table = table[[*(["paper"] if with_paper else []), reference, control, test_column, "differs?", "paper within CI?"]]
    table.attrs["n_tests"] = n_tests
    return table


def _reached(reported: paper.Reported | None, values: pd.Series, confidence: float, n_boot: int,
             seed: int) -> bool | None:
    if reported is None:
        return None
    low, high, n = paper_range(reported.value)
    if values.dtype == bool:
        return count_reached(int(values.sum()), len(values), low, confidence) if n is not None else None
    return mean_reached(values.astype(float).to_numpy(), low, high, confidence=confidence, n_boot=n_boot, seed=seed)


def fewest_runs(n_tests: int, alpha: float = 0.05) -> int:
    """The fewest paired runs n whose smallest exact two-sided p-value (2 / 2ⁿ: every pair differs the
    same way, McNemar exact or Wilcoxon signed-rank without ties), multiplied by Holm's ``n_tests``
    for the smallest p of the family, is below ``alpha``.

    Parameters
    ----------
    n_tests : int
        Size of the Holm family.
    alpha : float
        The significance level.
    """
    return max(1, math.floor(math.log2(2 * max(n_tests, 1) / alpha)) + 1)


def verdict_notes(results: Results, reference: str, control: str, *, n_tests: int = 1, alpha: float = 0.05,
                  confidence: float = 0.95) -> list[str]:
    """The lines printed under :func:`verdict_table`: the rule of "differs?" (the tests, Holm over
    ``n_tests``, ``alpha``; the smallest exact p-value the runs allow, 2 / 2ⁿ, Holm-adjusted, and
    :func:`fewest_runs`), the rule of "paper within CI?", and one line per condition of ``results``
    saying what it is (its ``description`` in ``config.toml``; "no description" when it has none).

    Parameters
    ----------
    results : Results
        The results folder of the table.
    reference, control : str
        The table's two conditions.
    n_tests : int
        Size of the table's Holm family (its ``attrs["n_tests"]``).
    alpha : float
        The level of "differs?".
    confidence : float
        Coverage of the intervals of "paper within CI?".

    Returns
    -------
    list of str
        The lines, in print order.
    """
    n = int(per_run(results.select([reference])).shape[0])
    floor = 2.0 / 2.0 ** n if n else math.nan
    level = f"{confidence * 100:g} %"
    lines = [
        f"differs?: {reference} against {control} paired by run, {TESTS['mcnemar_exact'][0]} ({TESTS['mcnemar_exact'][1]}) "
        f"for a yes/no outcome and {TESTS['wilcoxon'][0]} ({TESTS['wilcoxon'][1]}) for a number, Holm-adjusted over "
        f"the table's {n_tests} tests; yes when p < {alpha:g}. With {n} paired runs an exact test's p is at least "
        f"{floor:.2g}, Holm-adjusted at least {min(1.0, n_tests * floor):.2g}: a yes needs {fewest_runs(n_tests, alpha)} "
        f"or more runs.",
        f"paper within CI?: yes when the paper's number lies inside the {level} interval of the observed value of "
        f"{reference}: Clopper–Pearson for a count, the percentile bootstrap of the mean over runs for a number "
        f"(a range such as 2–3: when they overlap).",
    ]
    conditions = results.config.get("conditions", {})
    for name in results.conditions:
        description = (conditions.get(name) or {}).get("description") if isinstance(conditions, dict) else None
        lines.append(f"{name}: {description or 'no description in config.toml'}")
    return lines
