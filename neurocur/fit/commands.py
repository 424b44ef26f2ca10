"""The ``neurocur fit``, ``recover``, ``compare`` and ``sbi`` commands (their parsers: :mod:`neurocur.fit.cli`).

``fit DATA --experiment EXP [--condition C] --fit KEY ... [--bounds KEY=LOW:HIGH ...] [--ci profile|bootstrap]
[--bootstrap B] [--out DIR]`` writes ``DIR/fit.csv`` (``dataset, param, estimate, ci_low, ci_high``: each
data set, then the pooled fit; with ``--ci bootstrap`` the data sets' intervals are parametric-bootstrap
percentile intervals, :mod:`neurocur.fit.bootstrap`, their replicates in ``DIR/bootstrap.csv``, and the
pooled fit has none) and ``DIR/summary.json``: ``loglik, n_params, n_obs, aic, bic`` of the per-data-set
fits together; ``warnings`` (every warning line printed); ``ignored_columns`` (numeric columns of the table
the fit did not read: a signal given without ``--signal``); ``unseen_contexts`` (the world's contexts that
no data set visits); ``not_identified`` (per fit with any, the keys the data do not identify within the
bounds, :func:`neurocur.fit.mle.weak_keys`); then each fit's (``fits``, each with its ``not_identified``).
With ``--hierarchical`` (:mod:`neurocur.fit.hierarchical`; at least 2 data sets, profile intervals only)
``fit.csv`` holds each data set's MAP under the fitted group prior and its Laplace posterior's 95 % interval
(no pooled row), ``DIR/group.csv`` the group's ``param, mean, sd, ci_low, ci_high`` on the parameters' own scale
(then ``kind, mu, sigma, mu_se`` on the unbounded one), and ``summary.json`` the fit's
:meth:`~neurocur.fit.hierarchical.HierarchicalFit.summary` (``ibic``, ``ibic_laplace``, ``iterations``,
``converged``: false, and a warning, when ``--em-iterations`` stopped it) instead of the per-data-set scores;
``compare --hierarchical`` writes ``compare.csv`` (per data set and model: ``loglik`` at the MAP, ``n_params``,
``n_obs``, the Laplace ``log_evidence`` under the model's group prior), ``bms.csv`` (BMS on those log evidences)
and ``hierarchical.csv`` (per model: ``ibic, laplace_ibic``, the evidences, ``iterations, converged``), no figure.
``recover EXPERIMENT --fit KEY ...`` writes ``recovery.csv``, ``recovery_summary.csv`` and ``recovery.png``;
with ``--models C1 C2 ...`` also ``model_recovery.csv``, ``confusion_{aic,bic,heldout}.csv`` and
``confusion.png`` (while it runs, the tables so far are ``recovery.partial.csv`` and
``model_recovery.partial.csv``; ``compare``'s is ``compare.partial.csv``).
``sbi EXPERIMENT --prior KEY=LOW:HIGH ... --simulations N`` runs the training simulations into
``DIR/sbi_training/`` and trains NPE; with ``--data`` writes ``DIR/sbi.csv``, with ``--test N``
``sbi_recovery.csv``, ``sbi_recovery_summary.csv`` and ``sbi_recovery.png``.

Every command's output folder (:mod:`neurocur.fit.outdir`) is locked while it runs, replaced whole, and
has a ``manifest.json``: ``command``, ``arguments``, ``files`` (each file written, with its sha256),
``folders`` (kept from one run to the next: sbi's training runs), ``warnings`` and ``complete`` (false
until everything is written). Files are written whole (a temporary file renamed into place) inside the
output folder only, CSV cells that a spreadsheet would run escaped. Input checks (:mod:`neurocur.fit.checks`,
:mod:`neurocur.fit.data`, :func:`neurocur.fit.study.default_bounds`) refuse in one line what cannot be fitted
honestly (docs/fitting.md, "What a fit refuses").
"""

from __future__ import annotations

import argparse
import json
import math

import pandas as pd

from ..config import ConfigError
from .outdir import FitInterrupted, fit_output

__all__ = ["COMMANDS", "parse_bounds"]


def parse_bounds(text: str) -> tuple[str, tuple[float, float]]:
    """``KEY=LOW:HIGH`` as ``(key, (low, high))`` (an argparse type: ``--bounds``, and ``sbi``'s ``--prior``).

    Parameters
    ----------
    text : str
        ``KEY=LOW:HIGH``, e.g. ``LC.gain=0:60``; ``LOW`` and ``HIGH`` are numbers (``inf`` and ``-inf`` allowed)
        with ``LOW < HIGH``.

    Returns
    -------
    tuple of (str, (float, float))
        The key and its bounds.

    Raises
    ------
    argparse.ArgumentTypeError
        Without ``=`` or ``:``, with a bound that is not a number, or unless ``LOW < HIGH`` (argparse reports it
        on one line, naming the option).
    """
    key, sep, rng = text.partition("=")
    low, sep2, high = rng.partition(":")
    try:
        lo, hi = float(low), float(high)
    except ValueError:
        lo = hi = None
    if not sep or not sep2 or lo is None or not lo < hi:
        raise argparse.ArgumentTypeError(f"expected KEY=LOW:HIGH with LOW < HIGH, got {text!r}")
    return key, (lo, hi)


def _arguments(args) -> dict:
    """The command's arguments as the manifest records them."""
    return {key: value for key, value in vars(args).items() if key != "command"}


def _partial(out, stem: str):
    """A progress callback writing the table so far as ``OUT/STEM.partial.csv`` (whole) and saying how far it is."""
    def write(table) -> None:
        out.write_csv(f"{stem}.partial.csv", table)
        print(f"{stem}.partial.csv: {table['dataset'].nunique()} data sets", flush=True)
    return write


def _finish(out, stem: str, table) -> None:
    """Write ``OUT/STEM.csv`` whole and remove its partial table."""
    out.write_csv(f"{stem}.csv", table)
    out.remove(f"{stem}.partial.csv")


def _checked_data(args, experiment, conditions, decision: str = "LC", signal=None):
    """The data sets of ``args.data`` for the ``conditions``' world (the first's), the folder checked against the
    experiment (:func:`~neurocur.fit.checks.check_folder`), and what the fit would ignore (``data_warnings``)."""
    from .checks import check_folder, data_warnings
    from .models import load_fit_data

    check_folder(args.data, experiment, conditions)
    data = load_fit_data(args.data, conditions[0], columns=getattr(args, "columns", ()),
                         one_based=getattr(args, "one_based", False), decision=decision, signal=signal)
    return data, data_warnings(data, conditions[0].make_world().context_names, args.data)


def _cmd_fit(args) -> int:
    from .bootstrap import parametric_bootstrap
    from .mle import fit_table
    from .models import data_summary, fit_keys
    from .study import check_bound_keys, condition_of, default_bounds, fit_data, make_replays

    experiment, condition = condition_of(args.experiment, args.condition)
    args.keys = fit_keys(condition, args.keys)
    check_bound_keys(dict(args.bounds), args.keys)
    bounds = default_bounds(condition, args.keys, dict(args.bounds))
    _check_hierarchical(args)
    data, found = _checked_data(args, experiment, [condition], args.decision, args.signal)
    if args.hierarchical:
        return _fit_hierarchical(args, experiment, condition, bounds, data, found)
    with fit_output(args.out or f"results/fit-{experiment.name}", "fit", _arguments(args),
                    inputs=[args.data]) as out:
        for line in found["lines"]:
            out.warn(line)
        replays = make_replays(experiment, condition, data, args.keys, decision=args.decision, signal=args.signal)
        fits = fit_data(replays, bounds, starts=args.starts, seed=args.seed,
                        ci=0.95 if args.ci == "profile" else None)
        if args.ci == "bootstrap":  # per data set (fits[i] is data[i]'s); the pooled fit keeps no interval
            boots = [parametric_bootstrap(condition, fit.estimate, len(behaviour), bounds, replicates=args.bootstrap,
                                          seed=[args.seed, i], starts=args.starts, decision=args.decision,
                                          signal=args.signal, dataset=fit.dataset)
                     for i, (fit, behaviour) in enumerate(zip(fits, data))]
            for fit, boot in zip(fits, boots):
                fit.ci = boot.ci
            out.write_csv("bootstrap.csv", pd.concat([b.replicates for b in boots]))
        out.write_csv("fit.csv", fit_table(fits))
        unidentified = {f.dataset: f.unidentified for f in fits if f.unidentified}
        for dataset, keys in unidentified.items():
            out.warn(f"data set {dataset!r}: the data do not identify {', '.join(keys)} within the bounds (a flat "
                     "profile, or an information matrix that is (near) singular at the estimate, as for parameters "
                     "that act only as a product); fix one of them or fit fewer")
        each = [f for f in fits if f.dataset != "pooled" or len(fits) == 1]
        loglik, k, n = sum(f.loglik for f in each), sum(f.n_params for f in each), sum(f.n_obs for f in each)
        summary = {"experiment": experiment.name, "condition": condition.name, "fitted": list(args.keys),
                   "bounds": {key: list(v) for key, v in bounds.items()},
                   "intervals": args.ci if args.ci == "profile" else f"bootstrap ({args.bootstrap} replicates)",
                   "loglik": loglik, "n_params": k, "n_obs": n,
                   "aic": 2 * k - 2 * loglik, "bic": k * math.log(n) - 2 * loglik,
                   "warnings": list(out.manifest["warnings"]), "ignored_columns": found["ignored_columns"],
                   "unseen_contexts": found["unseen_contexts"], "not_identified": unidentified,
                   "fits": [f.summary() | {"estimate": f.estimate, "not_identified": f.unidentified} for f in fits],
                   **data_summary(data, columns=args.columns, one_based=args.one_based)}
        out.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=True) + "\n")
    for f in fits:
        print(f"{f.dataset}: " + ", ".join(f"{key} = {v:.4g}" + (f" [{f.ci[key][0]:.4g}, {f.ci[key][1]:.4g}]"
                                                                 if key in f.ci else "")
                                           for key, v in f.estimate.items()) + f"  (log L = {f.loglik:.2f})")
    print(out.root / "fit.csv")
    return 0


def _check_hierarchical(args, data=None) -> None:
    """Refuse in one line what a hierarchical fit cannot honour: bootstrap intervals, a single data set
    (``data``, once read), ``--no-loo``; and its options without ``--hierarchical``."""
    if not args.hierarchical:
        for flag, value in (("--em-iterations", args.em_iterations), ("--evidence-samples", args.evidence_samples),
                            ("--jobs", args.jobs)):
            if value is not None:
                raise ConfigError(flag, None, "--hierarchical with it (an option of the hierarchical fit)",
                                  "no --hierarchical")
        return
    if getattr(args, "ci", "profile") == "bootstrap":
        raise ConfigError("--hierarchical", "--ci", "profile (a hierarchical fit's intervals are its Laplace posterior's; "
                          "a bootstrap of the group is not implemented)", "bootstrap")
    if getattr(args, "no_loo", False):
        raise ConfigError("--hierarchical", "--no-loo", "no --no-loo (a hierarchical comparison has no "
                          "leave-one-data-set-out fits)", "--no-loo")
    if data is not None and len(data) < 2:
        raise ConfigError(args.data, None, "at least 2 data sets for --hierarchical (a group prior is fitted to "
                          "several subjects)", f"{len(data)} data set")


def _fit_hierarchical(args, experiment, condition, bounds, data, found) -> int:
    """``fit --hierarchical``: fit.csv (each data set's MAP and Laplace interval), group.csv, summary.json."""
    from ..experiments.processes import worker_count
    from .hierarchical import MAX_ITER, N_SAMPLES, fit_hierarchical
    from .models import data_summary
    from .study import make_replays

    _check_hierarchical(args, data)
    with fit_output(args.out or f"results/fit-{experiment.name}", "fit", _arguments(args),
                    inputs=[args.data]) as out:
        for line in found["lines"]:
            out.warn(line)
        replays = make_replays(experiment, condition, data, args.keys, decision=args.decision, signal=args.signal)
        fit = fit_hierarchical(replays, bounds, names=[r.behaviour.name for r in replays], seed=args.seed,
                               starts=args.starts, max_iter=args.em_iterations or MAX_ITER,
                               n_samples=args.evidence_samples or N_SAMPLES, workers=worker_count(args.jobs, len(data)))
        _warn_unconverged(out, condition.name, fit)
        out.write_csv("fit.csv", fit.subjects)
        out.write_csv("group.csv", fit.group)
        summary = {"experiment": experiment.name, "condition": condition.name, "fitted": list(args.keys),
                   "bounds": {key: list(v) for key, v in bounds.items()},
                   "intervals": "hierarchical: each data set's Laplace posterior under the fitted group prior",
                   **fit.summary(), "warnings": list(out.manifest["warnings"]),
                   "ignored_columns": found["ignored_columns"], "unseen_contexts": found["unseen_contexts"],
                   **data_summary(data, columns=args.columns, one_based=args.one_based)}
        out.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=True) + "\n")
    print(fit.group[["param", "mean", "sd", "ci_low", "ci_high"]].to_string(index=False))
    print(f"iBIC = {fit.ibic:.2f} (Laplace {fit.ibic_laplace:.2f}), {fit.iterations} E-steps"
          + ("" if fit.converged else ", not converged"))
    print(out.root / "fit.csv")
    return 0


def _warn_unconverged(out, model: str, fit) -> None:
    if not fit.converged:
        out.warn(f"{model}: the hierarchical EM did not converge within {fit.iterations} E-steps (--em-iterations): "
                 "its group parameters, MAPs and iBIC are those of the last E-step")


def _cmd_recover(args) -> int:
    from .models import fit_keys, model_keys
    from .recovery import (
        confusion,
        confusion_figure,
        model_recovery,
        parameter_recovery,
        recovery_figure,
        recovery_summary,
    )
    from .study import check_bound_keys, condition_of, default_bounds, model_bounds

    experiment, condition = condition_of(args.experiment, args.condition)
    keys = fit_keys(condition, args.keys)
    check_bound_keys(dict(args.bounds), keys)
    bounds = default_bounds(condition, keys, dict(args.bounds))
    if args.models:
        models, bounds_of = model_bounds(experiment, args.models, model_keys(experiment, args.models, args.keys),
                                         dict(args.bounds))
    with fit_output(args.out or f"results/recover-{experiment.name}", "recover", _arguments(args)) as out:
        table = parameter_recovery(condition, bounds, n_datasets=args.datasets, n_episodes=args.episodes,
                                   seed=args.seed, starts=args.starts, decision=args.decision, signal=args.signal,
                                   progress=_partial(out, "recovery"), intervals=args.ci, bootstrap=args.bootstrap)
        summary = recovery_summary(table)
        _finish(out, "recovery", table)
        out.write_csv("recovery_summary.csv", summary)
        out.write_figure("recovery.png", recovery_figure(table))
        print(summary.to_string(index=False))
        if args.models:
            mr = model_recovery(models, bounds_of, n_datasets=args.datasets, n_episodes=args.episodes,
                                seed=args.seed, decision=args.decision, progress=_partial(out, "model_recovery"))
            _finish(out, "model_recovery", mr)
            for by in ("aic", "bic", "heldout"):
                m = confusion(mr, by)
                out.write_csv(f"confusion_{by}.csv", m, index=True)
                print(f"confusion by {by}:\n{m.round(2).to_string()}")
            out.write_figure("confusion.png", confusion_figure(mr))
    print(out.root)
    return 0


def _cmd_sbi(args) -> int:
    from neurocur.experiments.executors import executor_for

    executor = executor_for(args.scheduler, args.jobs)
    executor.start()  # the workers' fork server imports the model, never torch
    from .recovery import recovery_figure, recovery_summary
    from .sbi import SBIStudy
    from .study import condition_of

    try:
        prior = dict(map(parse_bounds, args.prior))
    except argparse.ArgumentTypeError as exc:
        raise ValueError(f"--prior: {exc}") from None
    experiment, condition = condition_of(args.experiment, args.condition)
    n_contexts = len(condition.make_world().context_names)
    data, found = _checked_data(args, experiment, [condition]) if args.data else ([], {"lines": []})
    with fit_output(args.out or f"results/sbi-{experiment.name}", "sbi", _arguments(args),
                    inputs=[args.data] if args.data else [], folders=("sbi_training", "sbi_test")) as out:
        for line in found["lines"]:
            out.warn(line)
        study = SBIStudy(experiment, condition.name, prior, out.root, args.steps or experiment.steps, args.seed)
        training, held_out = study.simulate(executor, simulations=args.simulations, runs=args.runs, tests=args.test)
        sample = study.fit(training, n_contexts, epochs=args.epochs)
        if data:
            table = study.posterior(sample, data, n_contexts)
            out.write_csv("sbi.csv", table)
            print(table.to_string(index=False))
        if args.test:
            table = study.recovery(sample, held_out, n_contexts)
            out.write_csv("sbi_recovery.csv", table)
            out.write_csv("sbi_recovery_summary.csv", recovery_summary(table))
            out.write_figure("sbi_recovery.png", recovery_figure(table))
            print(recovery_summary(table).to_string(index=False))
    print(out.root)
    return 0


def _cmd_compare(args) -> int:
    from .compare import bms_table, compare_models, comparison_figure, totals
    from .models import model_keys
    from .study import condition_of, model_bounds

    experiment, _ = condition_of(args.experiment, None)
    models, bounds_of = model_bounds(experiment, args.models, model_keys(experiment, args.models, args.keys),
                                     dict(args.bounds))
    _check_hierarchical(args)
    data, found = _checked_data(args, experiment, list(models.values()), args.decision, args.signal)
    if args.hierarchical:
        return _compare_hierarchical(args, experiment, models, bounds_of, data, found)
    with fit_output(args.out or f"results/compare-{experiment.name}", "compare", _arguments(args),
                    inputs=[args.data]) as out:
        for line in found["lines"]:
            out.warn(line)
        table = compare_models(experiment, data, models, bounds_of, decision=args.decision, signal=args.signal,
                               starts=args.starts, seed=args.seed, loo=not args.no_loo,
                               progress=_partial(out, "compare"))
        selection = bms_table(table)
        _finish(out, "compare", table)
        out.write_csv("bms.csv", selection)
        out.write_figure("comparison.png", comparison_figure(table, selection))
    print(totals(table, selection).round(3).to_string())
    print(out.root)
    return 0


def _compare_hierarchical(args, experiment, models, bounds_of, data, found) -> int:
    """``compare --hierarchical``: compare.csv (per data set and model), bms.csv, hierarchical.csv (per model)."""
    from ..experiments.processes import worker_count
    from .compare import bms_table, compare_hierarchical
    from .hierarchical import MAX_ITER, N_SAMPLES

    _check_hierarchical(args, data)
    with fit_output(args.out or f"results/compare-{experiment.name}", "compare", _arguments(args),
                    inputs=[args.data]) as out:
        for line in found["lines"]:
            out.warn(line)
        table, ranked, fits = compare_hierarchical(
            experiment, data, models, bounds_of, decision=args.decision, signal=args.signal, starts=args.starts,
            seed=args.seed, max_iter=args.em_iterations or MAX_ITER, n_samples=args.evidence_samples or N_SAMPLES,
            progress=_partial(out, "compare"), workers=worker_count(args.jobs, len(data)))
        for name, fit in fits.items():
            _warn_unconverged(out, name, fit)
        selection = bms_table(table, "log_evidence")
        _finish(out, "compare", table)
        out.write_csv("bms.csv", selection)
        out.write_csv("hierarchical.csv", ranked)
    print(ranked.join(selection.set_index("model"), on="model").sort_values("ibic", kind="stable")
          .round(3).to_string(index=False))
    print(out.root)
    return 0


def _interruptible(command):
    """``command``, a Ctrl-C before its output folder is open (nothing written) becoming :class:`FitInterrupted`."""
    def run(args) -> int:
        try:
            return command(args)
        except FitInterrupted:
            raise
        except KeyboardInterrupt:
            raise FitInterrupted("nothing written") from None
    return run


#: the subcommands, by name
COMMANDS = {name: _interruptible(command) for name, command in
            {"fit": _cmd_fit, "recover": _cmd_recover, "compare": _cmd_compare, "sbi": _cmd_sbi}.items()}
