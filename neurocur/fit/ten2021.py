"""Ten, Kaushik, Oudeyer & Gottlieb (2021)'s posted trial data as neurocur trial tables.

Ten et al. 2021 (Nature Communications 12:5977, "Humans monitor learning progress in
curiosity-driven exploration"; `docs/ten2021.md`) let people guess the food preference of
monsters from four families, one learning activity each: a 1-dimensional rule (``1D``), a
1-dimensional rule with an irrelevant dimension (``I1D``), a 2-dimensional rule (``2D``) and no
rule (``R``). 60 forced trials (15 per activity) came first, then 250 free choices; one group was
left free (``free``, the paper's IG), the other told it would be tested (``strat``, EG; its file
has the 60 test trials after free play).

The first author posted the trials (``pipeline_data/s0/main_free.csv`` and ``main_strat.csv`` of
the GitHub repository ``alex-ten/Exploration``; no licence: neurocur never ships them, the user
gives the path). Their columns: ``sid, trial, condition, stage, blockTrial, family, D1, D2,
category, choice, correct, switch, rt``. What they mean, checked on the files:

- ``category`` is the activity (1 = 1D, 2 = I1D, 3 = 2D, 4 = R); ``family`` is the monster
  family shown (1 Bear, 2 Bunny, 3 GreenMonster, 4 Squid). Which family plays which activity was
  drawn per participant (all 24 assignments occur), and is fixed within a participant (checked);
- ``choice`` is the food the participant answered (1–8), ``correct`` whether it was right;
- ``stage`` 0 = forced, 1 = free, 2 = test; ``trial`` runs 1, 2, ... over all stages;
- ``condition`` (0/1, half the participants of each file) is a factor of the author's earlier
  analyses, absent from the paper's own raw data (Zenodo 10.5281/zenodo.5068243) and not analysed
  in the paper; it is kept as a column and used by nothing here. The group is the file.

:func:`read_ten2021` converts one file into the trial-table columns ``subject, trial, choice,
outcome, rt`` (``choice`` the activity's name) plus ``stage, group, sid, condition, family,
category, response, block_trial, d1, d2, switch``. :func:`paper_exclusions` applies the paper's
exclusion (a participant whose mean response bias lies more than 2 SD above the mean of both
groups pooled), which leaves the paper's 186 and 196 participants of the posted 199 and 201.
``python -m neurocur.fit.ten2021 FREE STRAT --out DIR`` runs the descriptive study of
docs/hypotheses.md, entry 16.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..config import ConfigError
from .files import read_table

__all__ = ["ACTIVITIES", "COLUMNS", "FREE_TRIALS", "GROUPS", "STAGES", "free_play", "paper_exclusions",
           "read_ten2021", "read_ten2021_groups", "response_bias"]

#: The activities by ``category`` (1–4), easiest first; R has no rule.
ACTIVITIES = ("1D", "I1D", "2D", "R")
#: The columns of a posted file.
COLUMNS = ("sid", "trial", "condition", "stage", "blockTrial", "family", "D1", "D2", "category", "choice",
           "correct", "switch", "rt")
#: ``stage`` codes.
STAGES = {0: "forced", 1: "free", 2: "test"}
#: The two instruction groups, as the files name them (free: the paper's IG; strat: EG).
GROUPS = ("free", "strat")
#: Free-play trials per participant in the paper.
FREE_TRIALS = 250
#: The paper's exclusion: response bias above the mean plus this many SDs.
RESPONSE_BIAS_SD = 2.0

#: Allowed values of the coded columns.
_CODES = {"category": (1, 2, 3, 4), "family": (1, 2, 3, 4), "stage": tuple(STAGES), "correct": (0, 1),
          "switch": (0, 1), "condition": (0, 1)}


def _group_of(path: Path, group: str | None) -> str:
    if group is not None:
        if group not in GROUPS:
            raise ConfigError(path, "group", f"one of {', '.join(GROUPS)}", repr(group))
        return group
    named = [g for g in GROUPS if g in path.name.lower()]
    if len(named) != 1:
        raise ConfigError(path, "group", "group='free' or 'strat' (the file name names neither, or both)",
                          repr(path.name))
    return named[0]


def _integers(table: pd.DataFrame, path: Path) -> pd.DataFrame:
    """Every column as int64, each value checked: present, whole and, for a coded column, a known code."""
    out = {}
    for column in COLUMNS:
        values = pd.to_numeric(table[column], errors="coerce")
        bad = values.isna() | (values != np.floor(values))
        if bad.any():
            row = int(np.flatnonzero(bad.to_numpy())[0])
            raise ConfigError(path, column, "whole numbers", f"{table[column].iloc[row]!r} in data row {row + 1}")
        values = values.astype(np.int64)
        codes = _CODES.get(column)
        if codes is not None and not values.isin(codes).all():
            row = int(np.flatnonzero(~values.isin(codes).to_numpy())[0])
            raise ConfigError(path, column, f"one of {', '.join(map(str, codes))}",
                              f"{values.iloc[row]} in data row {row + 1}")
        if column == "rt" and (values < 0).any():
            raise ConfigError(path, column, "response times >= 0 (ms)", f"{values.min()}")
        out[column] = values
    return pd.DataFrame(out)


def _check_participants(table: pd.DataFrame, path: Path) -> None:
    """Trials numbered 1, 2, ... in order, stages in order, one activity per family and one condition."""
    by = table.groupby("sid", sort=False)
    position = by.cumcount() + 1
    if (table["trial"] != position).any():
        row = int(np.flatnonzero((table["trial"] != position).to_numpy())[0])
        raise ConfigError(path, "trial", "each participant's trials numbered 1, 2, ... in order, on consecutive "
                          "rows", f"trial {table['trial'].iloc[row]} of participant {table['sid'].iloc[row]}")
    if (by["stage"].diff().fillna(0) < 0).any():
        sid = table.loc[by["stage"].diff().fillna(0) < 0, "sid"].iloc[0]
        raise ConfigError(path, "stage", "forced, then free, then test trials", f"participant {sid} out of order")
    for column, key in (("category", ["sid", "family"]), ("condition", ["sid"])):
        counts = table.groupby(key)[column].nunique()
        if (counts > 1).any():
            raise ConfigError(path, column, f"one {column} per {' and '.join(key)}",
                              f"several for {counts.index[counts > 1][0]}")


def read_ten2021(path, group: str | None = None) -> pd.DataFrame:
    """One posted file (``main_free.csv`` or ``main_strat.csv``) as a trial table, every row kept.

    Columns: ``subject`` (``"GROUP-SID"``, unique across the two files), ``trial`` (the file's running
    number, 1, 2, ... over all stages), ``choice`` (the activity: ``"1D"``, ``"I1D"``, ``"2D"``,
    ``"R"``), ``outcome`` (correct, 0/1), ``rt`` (ms), ``stage`` (``"forced"``, ``"free"``,
    ``"test"``), ``group``, ``sid``, ``condition``, ``family``, ``category`` (1–4), ``response``
    (the food answered, the file's ``choice``), ``block_trial``, ``d1``, ``d2``, ``switch``.

    A missing column, a value that is not a whole number or not a known code, trials out of
    order, or a family that changes activity is a :class:`~neurocur.config.ConfigError` naming
    the file and the column; a symbolic link or a FIFO as ``path`` is refused.

    Parameters
    ----------
    path : path
        The posted file.
    group : str, optional
        ``"free"`` or ``"strat"``; by default the one the file name names.

    Returns
    -------
    pandas.DataFrame
        One row per trial.
    """
    path = Path(path)
    group = _group_of(path, group)
    raw = read_table(path, (".csv",), "a regular CSV file", header=", ".join(COLUMNS), dtype=str,
                     keep_default_na=False)
    missing = [c for c in COLUMNS if c not in raw.columns]
    if missing:
        raise ConfigError(path, missing[0], f"the posted columns {', '.join(COLUMNS)}", "no such column")
    if raw.empty:
        raise ConfigError(path, None, "at least one trial", "no rows")
    table = _integers(raw, path)
    _check_participants(table, path)
    return pd.DataFrame({
        "subject": group + "-" + table["sid"].astype(str),
        "trial": table["trial"],
        "choice": table["category"].map(dict(enumerate(ACTIVITIES, start=1))),
        "outcome": table["correct"],
        "rt": table["rt"].astype(float),
        "stage": table["stage"].map(STAGES),
        "group": group,
        "sid": table["sid"],
        "condition": table["condition"],
        "family": table["family"],
        "category": table["category"],
        "response": table["choice"],
        "block_trial": table["blockTrial"],
        "d1": table["D1"],
        "d2": table["D2"],
        "switch": table["switch"],
    })


def response_bias(table: pd.DataFrame) -> pd.Series:
    """Each subject's response bias: for each monster family, the share of its trials given the
    family's most frequent answer, averaged over the families (every stage counted, as the paper's
    code did). 0.5 answers at chance between a family's two foods; 1 always answers the same.

    Parameters
    ----------
    table : pandas.DataFrame
        A trial table of :func:`read_ten2021`.

    Returns
    -------
    pandas.Series
        By subject.
    """
    counts = table.groupby(["subject", "family", "response"], sort=False).size()
    top = counts.groupby(level=["subject", "family"], sort=False).max()
    share = top / counts.groupby(level=["subject", "family"], sort=False).sum()
    return share.groupby(level="subject", sort=False).mean().rename("response_bias")


def paper_exclusions(table: pd.DataFrame, *, apply: bool = True,
                     sd: float = RESPONSE_BIAS_SD) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The paper's exclusion, on a table of one or both groups: a subject is excluded when its
    :func:`response_bias` exceeds the mean plus ``sd`` sample SDs of all subjects of ``table``
    (the paper pooled the two groups: give both, :func:`read_ten2021_groups`).

    The paper's code also had an allocation criterion, switched off for the paper, so it is not
    applied here.

    Parameters
    ----------
    table : pandas.DataFrame
        A trial table of one or both groups (:func:`read_ten2021`).
    apply : bool
        Drop the excluded subjects' trials (False: keep every trial, only report).
    sd : float
        The threshold's number of sample SDs above the mean.

    Returns
    -------
    (pandas.DataFrame, pandas.DataFrame)
        The kept trials, and one row per subject: ``subject, group, response_bias, threshold, excluded``.
    """
    bias = response_bias(table)
    threshold = float(bias.mean() + sd * bias.std(ddof=1))
    report = pd.DataFrame({"subject": bias.index,
                           "group": table.groupby("subject", sort=False)["group"].first().loc[bias.index].to_numpy(),
                           "response_bias": bias.to_numpy(), "threshold": threshold,
                           "excluded": (bias > threshold).to_numpy()})
    if not apply:
        return table, report
    dropped = set(report.loc[report["excluded"], "subject"])
    return table[~table["subject"].isin(dropped)].reset_index(drop=True), report


def read_ten2021_groups(free_path, strat_path, *, exclude: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Both posted files as one trial table, with :func:`paper_exclusions` over the two pooled.

    Parameters
    ----------
    free_path, strat_path : str or Path
        The posted ``main_free.csv`` and ``main_strat.csv``.
    exclude : bool
        Apply the paper's exclusions (False keeps everyone; the report is made either way).

    Returns
    -------
    tuple of (DataFrame, DataFrame)
        The trial table (:func:`read_ten2021`'s columns) and the exclusion report.
    """
    table = pd.concat([read_ten2021(free_path, "free"), read_ten2021(strat_path, "strat")], ignore_index=True)
    return paper_exclusions(table, apply=exclude)


def free_play(table: pd.DataFrame, n_trials: int = FREE_TRIALS) -> pd.DataFrame:
    """Each subject's first ``n_trials`` free-play trials, with ``free_trial`` = 1 .. ``n_trials``.

    Some free-instructions participants played past 250 free trials in the posted file (up to
    277); the paper used the first 250 (trial <= 310). A subject with fewer is a ValueError.

    Parameters
    ----------
    table : DataFrame
        A trial table of :func:`read_ten2021`.
    n_trials : int
        Free trials kept per subject.

    Returns
    -------
    DataFrame
        The free-play rows, in subject and trial order, with ``free_trial``.
    """
    free = table[table["stage"] == "free"].sort_values(["subject", "trial"], kind="stable")
    free = free.assign(free_trial=free.groupby("subject", sort=False).cumcount() + 1)
    short = free.groupby("subject", sort=False)["free_trial"].max()
    short = short[short < n_trials]
    if len(short):
        raise ValueError(f"free_play expected {n_trials} free-play trials per subject, got {int(short.iloc[0])} "
                         f"for subject {short.index[0]}")
    return free[free["free_trial"] <= n_trials].reset_index(drop=True)


def _study(table: pd.DataFrame, n_bins: int, n_permutations: int, seed: int) -> dict:
    """The tables and figures of docs/hypotheses.md, entry 16, from a trial table of both groups."""
    from ..analysis.figures.choice_shares import fig_choice_shares, fig_peak_bins
    from ..analysis.stats.choice_shares import (
        ordered_peaks,
        peak_bins,
        permutation_tests,
        share_array,
        share_change,
        share_summary,
    )

    order, falling = [0, 1, 2], ACTIVITIES.index("R")
    free = free_play(table)
    shares, summaries, peaks, per_subject = {}, {}, {}, []
    for group in GROUPS:
        shares[group], subjects = share_array(free[free["group"] == group], ACTIVITIES, n_bins=n_bins)
        summaries[group] = share_summary(shares[group], ACTIVITIES).assign(group=group)
        peaks[group] = peak_bins(shares[group])
        per_subject.append(pd.DataFrame({"subject": subjects, "group": group,
                                         **{f"peak_{a}": peaks[group][:, k] for k, a in enumerate(ACTIVITIES)},
                                         "ordered": ordered_peaks(peaks[group], order),
                                         "change_R": share_change(shares[group], falling)}))
    trials_per_bin = FREE_TRIALS // n_bins if FREE_TRIALS % n_bins == 0 else None
    return {"shares": pd.concat(summaries.values(), ignore_index=True),
            "peaks": pd.concat(per_subject, ignore_index=True),
            "tests": permutation_tests(shares, order, falling, n_permutations=n_permutations, seed=seed),
            "figures": {"shares": fig_choice_shares(summaries, ACTIVITIES, trials_per_bin=trials_per_bin),
                        "peaks": fig_peak_bins(peaks, ACTIVITIES)}}


def main(argv=None) -> int:
    """``python -m neurocur.fit.ten2021 FREE STRAT --out DIR``: the descriptive study of
    docs/hypotheses.md, entry 16, written into DIR (``participants.csv``, ``shares.csv``,
    ``peaks.csv``, ``tests.csv``, ``shares.png``, ``peaks.png``)."""
    import argparse
    import sys

    from ..analysis.figures.style import save_figures
    from ..analysis.stats.choice_shares import N_PERMUTATIONS
    from ..results.safeio import atomic_text

    parser = argparse.ArgumentParser(prog="python -m neurocur.fit.ten2021", description=__doc__.splitlines()[0])
    parser.add_argument("free", help="the free-instructions group's file (main_free.csv)")
    parser.add_argument("strat", help="the test-instructions group's file (main_strat.csv)")
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument("--keep-all", action="store_true", help="keep every participant (no exclusion)")
    parser.add_argument("--bins", type=int, default=10, help="bins of the 250 free-play trials (default 10)")
    parser.add_argument("--permutations", type=int, default=N_PERMUTATIONS, help="shuffles of each test")
    parser.add_argument("--seed", type=int, default=2021, help="seed of the shuffles (default 2021)")
    args = parser.parse_args(argv)
    if not 1 <= args.bins <= FREE_TRIALS or args.permutations < 1:
        parser.error("--bins expected 1 to 250 and --permutations at least 1")
    out = Path(args.out)
    if out.is_symlink():
        parser.error(f"--out: expected a folder, not a symbolic link, got {str(out)!r}")
    try:
        table, report = read_ten2021_groups(args.free, args.strat, exclude=not args.keep_all)
    except ConfigError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    found = _study(table, args.bins, args.permutations, args.seed)
    out.mkdir(parents=True, exist_ok=True)
    for name, frame in (("participants", report), ("shares", found["shares"]), ("peaks", found["peaks"]),
                        ("tests", found["tests"])):
        atomic_text(out / f"{name}.csv", frame.to_csv(index=False))
    save_figures(found["figures"], out)
    kept = report[~report["excluded"]] if not args.keep_all else report
    counts = ", ".join(f"{g} {int((report['group'] == g).sum())} -> {int((kept['group'] == g).sum())}" for g in GROUPS)
    print(f"participants (posted -> analysed): {counts}")
    print(found["tests"].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"written to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
