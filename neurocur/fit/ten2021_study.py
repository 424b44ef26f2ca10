"""Hypothesis run 17 (docs/hypotheses.md): Ten et al. 2021's choice models compared on the posted data.

For each group of the posted files (Ten, Kaushik, Oudeyer & Gottlieb 2021, Nature Communications
12:5977; `docs/ten2021.md`), the participants kept by the paper's exclusion who mastered a learnable
activity (:func:`mastered`, the paper's NAM > 0) are fitted with every condition of the experiment
``ten2021`` (:data:`MODELS`): hierarchically (Huys et al. 2011; iBIC, and random-effects BMS with
protected exceedance probabilities, Stephan et al. 2009, Rigoux et al. 2014, on each participant's
Laplace log evidence under the group prior) and per participant by maximum likelihood (AIC, BIC on
the 249 scored choices). The likelihood is :mod:`neurocur.fit.ten2021_models`'.

    python -m neurocur.fit.ten2021_study compare FREE STRAT --out DIR
    python -m neurocur.fit.ten2021_study recover FREE STRAT --fits DIR --out DIR2
    python -m neurocur.fit.ten2021_study ppc FREE STRAT --fits DIR --out DIR3

``recover`` and ``ppc`` (:mod:`neurocur.fit.ten2021_checks`) read the fits ``compare`` wrote. ``--models persev``
runs hypothesis run 19's models instead (:data:`~neurocur.fit.ten2021_models.MODEL_SETS`: the utility models with
perseveration beside them), ``--models time`` run 20's (perseveration + PC + TIME, with and without LP).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..regions.ten2021 import WINDOW, activity_signals
from .bms import bms
from .hierarchical import MAX_ITER, N_SAMPLES
from .ten2021 import ACTIVITIES, GROUPS, free_play, read_ten2021_groups
from .ten2021_models import LP_MODELS, MODEL_SETS, MODELS, Session, fit_group, model_bounds, session_features

__all__ = ["LP_MODELS", "MODELS", "compare_group", "lp_verdict", "mastered", "model_bounds", "sessions_of"]

#: Correct answers in an activity's window that make it mastered (the paper's 13 of 15).
MASTERY = 13
#: The learnable activities (their indices in ACTIVITIES).
LEARNABLE = (0, 1, 2)
#: The summed protected exceedance probability of the LP models that the rule asks for.
PXP_LEVEL = 0.95
#: Per model set, the secondary AIC comparison's models: the simpler ones, then the one with LP that is set against the
#: best of them (PC, LP and PC + LP: the paper's Fig. 5a for ``paper``; hypothesis run 20's two for ``time``).
AIC_CONTRASTS = {"paper": ("pc", "lp", "pc_lp"), "persev": ("persev_pc", "persev_lp", "persev_pc_lp"),
                 "time": ("persev_pc_time", "persev_pc_lp_time")}


def mastered(choices, outcomes) -> bool:
    """The paper's NAM > 0: the competence (percent correct over the last 15 trials) of a learnable activity
    reached 13/15 at some point from the end of the forced phase to the end of the session.

    Parameters
    ----------
    choices : array of int
        The session's activity on each trial (indices into ``ACTIVITIES``), forced trials first.
    outcomes : array of float
        Each trial's outcome, 1 correct and 0 not.

    Returns
    -------
    bool
        Whether a learnable activity's competence reached :data:`MASTERY` of ``WINDOW`` after the forced phase.
    """
    choices = np.asarray(choices, dtype=np.int64)
    pc = activity_signals(np.r_[choices, 0], np.r_[np.asarray(outcomes, dtype=float), 0.0], len(ACTIVITIES))["pc"]
    return bool((pc[WINDOW * len(ACTIVITIES):, list(LEARNABLE)] * WINDOW >= MASTERY - 1e-9).any())


def sessions_of(table: pd.DataFrame) -> dict[str, list[tuple[str, np.ndarray, np.ndarray]]]:
    """Per group, each participant's session (name, activity indices, outcomes): the forced trials and the
    first 250 free ones (:func:`~neurocur.fit.ten2021.free_play`), for the participants who mastered a
    learnable activity (:func:`mastered`), in the order of their subject identifiers.

    Parameters
    ----------
    table : pandas.DataFrame
        A trial table of :func:`~neurocur.fit.ten2021.read_ten2021` (``subject, group, stage, trial, choice,
        outcome``), e.g. :func:`~neurocur.fit.ten2021.read_ten2021_groups`' after the paper's exclusion.

    Returns
    -------
    dict of str to list of (str, numpy.ndarray, numpy.ndarray)
        Per group of ``GROUPS`` (an empty list for a group without participants), the kept sessions.
    """
    trials = pd.concat([table[table["stage"] == "forced"], free_play(table)])
    trials = trials.sort_values(["subject", "trial"], kind="stable")
    code = {name: k for k, name in enumerate(ACTIVITIES)}
    out: dict[str, list] = {group: [] for group in GROUPS}
    for subject, rows in trials.groupby("subject", sort=False):
        choices = rows["choice"].map(code).to_numpy(dtype=np.int64)
        outcomes = rows["outcome"].to_numpy(dtype=np.float64)
        if mastered(choices, outcomes):
            out[str(rows["group"].iloc[0])].append((str(subject), choices, outcomes))
    return out


def lp_verdict(hierarchical: pd.DataFrame, selection: pd.DataFrame, lp_models: Sequence[str] = LP_MODELS) -> dict:
    """The declared rule of runs 17 and 19.

    Parameters
    ----------
    hierarchical : DataFrame
        A row per model: ``model``, ``ibic``.
    selection : DataFrame
        A row per model: ``model``, ``pxp`` (random-effects BMS).
    lp_models : sequence of str
        The models with a learning-progress component.

    Returns
    -------
    dict
        ``best_ibic``, ``lp_best`` (a: the lowest iBIC belongs to an LP model), ``lp_pxp``, ``lp_pxp_reached``
        (b: the LP models' summed PXP >= 0.95) and ``verdict`` (supported, partly supported, not supported).
    """
    best = str(hierarchical.loc[hierarchical["ibic"].idxmin(), "model"])
    pxp = float(selection.loc[selection["model"].isin(lp_models), "pxp"].sum())
    a, b = best in lp_models, pxp >= PXP_LEVEL
    return {"best_ibic": best, "lp_best": a, "lp_pxp": pxp, "lp_pxp_reached": b,
            "verdict": "supported" if a and b else "partly supported" if a or b else "not supported"}


def paper_comparison(ml: pd.DataFrame, contrast: Sequence[str] = AIC_CONTRASTS["paper"]) -> dict:
    """The paper's comparison of PC, LP and PC + LP by per-participant AIC (or of any simpler models against one
    with LP).

    Parameters
    ----------
    ml : DataFrame
        Per-participant maximum-likelihood fits: ``subject``, ``model``, ``aic``.
    contrast : sequence of str
        The simpler models, then the model set against the best of them: PC, LP and PC + LP
        (:data:`AIC_CONTRASTS`).

    Returns
    -------
    dict
        Each model's mean AIC (``mean_aic_<model>``), the participants whose last model's AIC is below the best of
        the others (``<last>_better``, and by at least 2, ``<last>_better_by_2``) and ``participants``.
    """
    *simpler, both = contrast
    aic = ml.pivot(index="subject", columns="model", values="aic")
    margin = aic[list(simpler)].min(axis=1) - aic[both]
    return {**{f"mean_aic_{m}": float(aic[m].mean()) for m in contrast},
            f"{both}_better": int((margin > 0).sum()), f"{both}_better_by_2": int((margin >= 2).sum()),
            "participants": int(len(aic))}


def compare_group(sessions: Sequence[Session], *, seed: int, starts: int = 3, n_samples: int = N_SAMPLES,
                  max_iter: int = MAX_ITER, models: str = "paper") -> dict:
    """The comparison of one group (module docstring).

    Parameters
    ----------
    sessions : sequence of Session
        The group's participants.
    seed, starts, n_samples, max_iter
        :func:`~neurocur.fit.ten2021_models.fit_group`'s options.
    models : str
        The model set, a key of :data:`~neurocur.fit.ten2021_models.MODEL_SETS`.

    Returns
    -------
    dict
        The tables of :func:`~neurocur.fit.ten2021_models.fit_group`, ``bms`` (on the Laplace evidences),
        ``bms_bic`` (on -BIC/2 of the per-participant fits), the rule's ``verdict`` and the AIC comparison of
        PC, LP and PC + LP (``paper``, :func:`paper_comparison`).
    """
    names, lp_models = MODEL_SETS[models]
    found = fit_group(sessions, model_bounds(names), seed=seed, starts=starts, n_samples=n_samples,
                      max_iter=max_iter)
    found["bms"] = bms(found["evidence"]).table(names)
    bic = found["ml"].pivot(index="subject", columns="model", values="bic").loc[[s.name for s in sessions], list(names)]
    found["bms_bic"] = bms(-bic.to_numpy() / 2).table(names)
    found["verdict"] = lp_verdict(found["hierarchical"], found["bms"], lp_models)
    found["paper"] = paper_comparison(found["ml"], AIC_CONTRASTS[models])
    return found


def comparison_figure(hierarchical: pd.DataFrame, selection: pd.DataFrame, models: str = "paper"):
    """Per group (a column each): the iBIC above the group's best per model, and the protected exceedance
    probabilities (the model set ``models``, its LP models in orange)."""
    from ..analysis.figures.style import figure

    names, lp_models = MODEL_SETS[models]
    groups = list(dict.fromkeys(hierarchical["group"]))
    fig, axes = figure(2, len(groups), figsize=(4.2 * len(groups), 6.0))
    for j, group in enumerate(groups):
        h = hierarchical[hierarchical["group"] == group].set_index("model").loc[list(names)]
        s = selection[selection["group"] == group].set_index("model").loc[list(names)]
        colours = ["tab:orange" if m in lp_models else "tab:grey" for m in names]
        delta = h["ibic"] - h["ibic"].min()
        axes[0, j].bar(range(len(names)), np.maximum(delta, 0.5), color=colours, log=True)
        axes[0, j].set(title=f"{group}: iBIC above the best (log scale)", ylabel="ΔiBIC")
        axes[1, j].bar(range(len(names)), s["pxp"], color=colours)
        axes[1, j].set(title=f"{group}: protected exceedance probability", ylabel="PXP", ylim=(0, 1))
        for ax in axes[:, j]:
            ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize=8)
    return fig


def run_compare(groups: Mapping[str, Sequence[Session]], *, seed: int, starts: int, n_samples: int,
                max_iter: int, models: str = "paper") -> tuple[dict[str, pd.DataFrame], object]:
    """:func:`compare_group` of each group (the model set ``models``), as the tables ``compare`` writes and its
    figure."""
    tables: dict[str, list] = {"hierarchical": [], "bms": [], "bms_bic": [], "maps": [], "ml": [], "verdict": []}
    for group, sessions in groups.items():
        found = compare_group(sessions, seed=seed, starts=starts, n_samples=n_samples, max_iter=max_iter,
                              models=models)
        for key in ("hierarchical", "bms", "bms_bic", "maps", "ml"):
            tables[key].append(found[key].assign(group=group))
        tables["verdict"].append(pd.DataFrame([{"group": group, "participants": len(sessions), **found["verdict"],
                                                **found["paper"]}]))
    out = {key: _group_first(pd.concat(frames, ignore_index=True)) for key, frames in tables.items()}
    return out, comparison_figure(out["hierarchical"], out["bms"], models)


def _group_first(frame: pd.DataFrame) -> pd.DataFrame:
    return frame[["group", *[c for c in frame.columns if c != "group"]]]


def winner(hierarchical: pd.DataFrame, group: str) -> str:
    """The group's model with the lowest iBIC among those with parameters (``random`` has none)."""
    rows = hierarchical[(hierarchical["group"] == group) & (hierarchical["model"] != "random")]
    return str(rows.loc[rows["ibic"].idxmin(), "model"])


def _read_fits(folder: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``hierarchical.csv`` and ``maps.csv`` of a ``compare`` folder."""
    from .files import read_table

    expected = f"the output folder of `compare` ({folder})"
    return tuple(read_table(folder / f"{name}.csv", (".csv",), expected) for name in ("hierarchical", "maps"))


def _recover(groups, raw, args, out: Path) -> None:
    from ..analysis.figures.style import save_figures
    from .ten2021_checks import model_recovery, parameter_recovery, recovery_figure, recovery_summary

    hierarchical, maps = _read_fits(Path(args.fits))
    model = winner(hierarchical, "free")
    fit = {"starts": args.starts, "n_samples": args.evidence_samples, "max_iter": args.em_iterations}
    figures = {}
    if args.only in (None, "parameters"):
        tables = [parameter_recovery(sessions, maps[(maps["group"] == group) & (maps["model"] == model)], model,
                                     seed=args.seed, **fit).assign(group=group, model=model)
                  for group, sessions in groups.items()]
        table = _group_first(pd.concat(tables, ignore_index=True))
        summary = recovery_summary(table)
        _write(out, {"parameter_recovery": table, "parameter_summary": summary})
        figures["parameter_recovery"] = recovery_figure(table)
        print(summary.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    if args.only in (None, "models"):
        free = groups["free"]
        drawn = np.sort(np.random.default_rng(args.seed).choice(len(free), min(args.participants, len(free)),
                                                                   replace=False))
        chosen = [free[i] for i in drawn]
        rows, confusion = model_recovery(chosen, maps[maps["group"] == "free"], seed=args.seed,
                                         models=MODEL_SETS[args.models][0], **fit)
        _write(out, {"model_recovery": rows, "confusion": confusion.reset_index()})
        figures["confusion"] = _confusion_figure(confusion)
        print(rows.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        print(confusion.to_string(float_format=lambda v: f"{v:.2f}"))
    save_figures(figures, out)


def _confusion_figure(confusion: pd.DataFrame):
    from ..analysis.figures.style import figure

    fig, axes = figure(1, 1, figsize=(4.6, 4.0))
    ax = axes[0, 0]
    ax.imshow(confusion.to_numpy(), vmin=0, vmax=1, cmap="Blues")
    for (r, c), v in np.ndenumerate(confusion.to_numpy()):
        ax.text(c, r, f"{v:.2f}", ha="center", va="center", fontsize=8, color="k" if v < 0.6 else "w")
    ax.set_xticks(range(confusion.shape[1]), confusion.columns, rotation=45, ha="right", fontsize=7)
    ax.set_yticks(range(confusion.shape[0]), confusion.index, fontsize=7)
    ax.set(title="largest Laplace log evidence per session", xlabel="fitted (winner)", ylabel="generating")
    return fig


def _ppc(groups, raw, args, out: Path) -> None:
    from ..analysis.figures.style import save_figures
    from .ten2021_checks import free_shares, posterior_predictive, ppc_figure

    hierarchical, maps = _read_fits(Path(args.fits))
    tables, replicates, people, model, titles = [], [], {}, {}, {}
    forced = WINDOW * len(ACTIVITIES)
    for group, sessions in groups.items():
        name = winner(hierarchical, group)
        rows, reps, shares = posterior_predictive(sessions, raw[group], maps[(maps["group"] == group) &
                                                                             (maps["model"] == name)],
                                                  seed=args.seed, replicates=args.replicates)
        tables.append(rows.assign(group=group, model=name))
        replicates.append(reps.assign(group=group, model=name))
        people[group] = free_shares(np.array([c[forced:] for _, c, _ in raw[group]]))
        model[group], titles[group] = shares, f"{group} ({len(sessions)}): people (points) and {name} (lines)"
    table = _group_first(pd.concat(tables, ignore_index=True))
    _write(out, {"ppc": table, "ppc_replicates": _group_first(pd.concat(replicates, ignore_index=True))})
    save_figures({"ppc": ppc_figure(people, model, titles)}, out)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))


def _write(out: Path, tables: Mapping[str, pd.DataFrame]) -> None:
    from ..results.safeio import atomic_text

    for name, frame in tables.items():
        atomic_text(out / f"{name}.csv", frame.to_csv(index=False))


def main(argv=None) -> int:
    """``python -m neurocur.fit.ten2021_study compare|recover|ppc FREE STRAT --out DIR [--fits DIR]``: the runs of
    docs/hypotheses.md, entry 17 (module docstring)."""
    import argparse
    import sys

    from ..analysis.figures.style import save_figures
    from ..config import ConfigError

    parser = argparse.ArgumentParser(prog="python -m neurocur.fit.ten2021_study", description=__doc__.splitlines()[0])
    parser.add_argument("step", choices=("compare", "recover", "ppc"))
    parser.add_argument("free", help="the free-instructions group's file (main_free.csv)")
    parser.add_argument("strat", help="the test-instructions group's file (main_strat.csv)")
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument("--fits", metavar="DIR", help="the folder `compare` wrote (recover, ppc)")
    parser.add_argument("--seed", type=int, default=2021, help="seed of the fits and simulations (default 2021)")
    parser.add_argument("--starts", type=int, default=3, help="starts of each fit (default 3)")
    parser.add_argument("--evidence-samples", type=int, default=N_SAMPLES, help="samples of the evidence")
    parser.add_argument("--em-iterations", type=int, default=MAX_ITER, help="E-steps at most")
    parser.add_argument("--replicates", type=int, default=200, help="replicates of each group (ppc)")
    parser.add_argument("--participants", type=int, default=100, help="participants drawn for model recovery")
    parser.add_argument("--only", choices=("parameters", "models"), help="recover: one of the two recoveries")
    parser.add_argument("--models", choices=tuple(MODEL_SETS), default="paper",
                        help="the model set: paper (run 17, the default), persev (run 19) or time (run 20)")
    args = parser.parse_args(argv)
    if args.step != "compare" and args.fits is None:
        parser.error(f"{args.step} expected --fits DIR, the folder `compare` wrote")
    if min(args.starts, args.evidence_samples, args.em_iterations, args.replicates) < 1 or args.participants < 3 \
            or args.seed < 0:
        parser.error("expected --starts, --evidence-samples, --em-iterations, --replicates >= 1, --participants >= 3 "
                     "and --seed >= 0")
    out = Path(args.out)
    if out.is_symlink() or out.exists() and not out.is_dir():
        parser.error(f"--out: expected a folder, not a symbolic link or a file, got {str(out)!r}")
    try:
        table, _ = read_ten2021_groups(args.free, args.strat)
        raw = sessions_of(table)
        groups = {group: [session_features(c, o, name=name) for name, c, o in found] for group, found in raw.items()}
        out.mkdir(parents=True, exist_ok=True)
        if args.step == "compare":
            tables, fig = run_compare(groups, seed=args.seed, starts=args.starts, n_samples=args.evidence_samples,
                                      max_iter=args.em_iterations, models=args.models)
            _write(out, tables)
            save_figures({"comparison": fig}, out)
            for key in ("hierarchical", "bms", "verdict"):
                print(tables[key].to_string(index=False, float_format=lambda v: f"{v:.5g}"))
        elif args.step == "recover":
            _recover(groups, raw, args, out)
        else:
            _ppc(groups, raw, args, out)
    except ConfigError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(f"written to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
