"""The ``neurocur fit``, ``recover``, ``compare`` and ``sbi`` subcommands (parsers and commands; :mod:`neurocur.cli` adds them).

``fit DATA --experiment EXP [--condition C] --fit KEY ... [--bounds KEY=LOW:HIGH ...] [--ci profile|bootstrap]
[--bootstrap B] [--out DIR]`` writes ``DIR/fit.csv`` (``dataset, param, estimate, ci_low, ci_high``: each
data set, then the pooled fit; with ``--ci bootstrap`` the data sets' intervals are parametric-bootstrap
percentile intervals, :mod:`neurocur.fit.bootstrap`, their replicates in ``DIR/bootstrap.csv``, and the
pooled fit has none) and ``DIR/summary.json``: ``loglik, n_params, n_obs, aic, bic`` of the per-data-set
fits together; ``warnings`` (every warning line printed); ``ignored_columns`` (numeric columns of the table
the fit did not read: a signal given without ``--signal``); ``unseen_contexts`` (the world's contexts that
no data set visits); ``not_identified`` (per fit with any, the keys the data do not identify within the
bounds, :func:`neurocur.fit.mle.weak_keys`); then each fit's (``fits``, each with its ``not_identified``).
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

from .outdir import FitInterrupted, fit_output

__all__ = ["COMMANDS", "FitInterrupted", "add_parsers"]


def _bounds(text: str) -> tuple[str, tuple[float, float]]:
    key, sep, rng = text.partition("=")
    low, sep2, high = rng.partition(":")
    try:
        lo, hi = float(low), float(high)
    except ValueError:
        lo = hi = None
    if not sep or not sep2 or lo is None or not lo < hi:
        raise argparse.ArgumentTypeError(f"expected KEY=LOW:HIGH with LOW < HIGH, got {text!r}")
    return key, (lo, hi)


def _signal(text: str) -> tuple[str, str]:
    region, sep, column = text.partition("=")
    if not sep or not region or not column:
        raise argparse.ArgumentTypeError(f"expected REGION=COLUMN (e.g. HPC=error), got {text!r}")
    return region, column


def _common(p: argparse.ArgumentParser, *, condition: bool = True, keys_required: bool = True) -> None:
    if condition:
        p.add_argument("--condition", metavar="NAME", help="the experiment's condition whose circuit to fit "
                       "(default: the first)")
    p.add_argument("--fit", dest="keys", action="append", required=keys_required, default=[], metavar="KEY",
                   help="a parameter to fit, REGION.param (repeatable), e.g. LC.gain, PFC.alpha (fit and compare: "
                   "default the condition's declared free parameters)")
    p.add_argument("--bounds", action="append", type=_bounds, default=[], metavar="KEY=LOW:HIGH",
                   help="search range of a fitted parameter (default: its declared range, when finite)")
    p.add_argument("--signal", type=_signal, metavar="REGION=COLUMN",
                   help="signal replay: REGION emits the data's per-episode COLUMN instead of computing it")
    p.add_argument("--decision", default="LC", metavar="REGION", help="the decision region (default LC)")
    p.add_argument("--starts", type=_count(1, "a number of optimiser starts of at least 1"), default=5, metavar="N",
                   help="optimiser starts per fit (default 5)")
    p.add_argument("--seed", type=_count(0, "an integer >= 0"), default=0, metavar="N",
                   help="seed of the starts (default 0)")
    p.add_argument("--out", metavar="DIR", help="output folder")


def _count(low: int, expected: str):
    """An argparse type: an integer >= ``low``, checked before any folder is made; the error says ``expected``."""
    def convert(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low:
            raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
        return value
    return convert


_replicates = _count(2, "a number of bootstrap replicates of at least 2")


def _intervals(p: argparse.ArgumentParser) -> None:
    p.add_argument("--ci", choices=("profile", "bootstrap"), default="profile",
                   help="95%% intervals by profile likelihood (default) or parametric bootstrap (percentile "
                   "intervals of --bootstrap refits of data sets simulated at the estimate)")
    p.add_argument("--bootstrap", type=_replicates, default=200, metavar="B",
                   help="bootstrap replicates per data set with --ci bootstrap (default 200; cost: B fits)")


def _trial_table(p: argparse.ArgumentParser) -> None:
    """A trial table's options (:mod:`neurocur.fit.trials`, :mod:`neurocur.fit.models`)."""
    p.add_argument("--columns", action="append", default=[], metavar="KEY=NAME,...",
                   help="a trial table's column names: KEY one of subject, trial, choice, outcome, rt "
                   "(e.g. subject=subjID,outcome=correct)")
    p.add_argument("--one-based", action="store_true",
                   help="a trial table's integer choice codes start at 1 (never guessed)")


def _parser(sub, name: str, help: str, description: str, example: str) -> argparse.ArgumentParser:
    """A subcommand's parser: its one-line ``help``, its ``description`` and one example after it."""
    return sub.add_parser(name, help=help, description=description, epilog=f"example:\n  {example}\n",
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def _data(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", metavar="DATA", help="a behaviour table (.csv, .parquet) or a results folder")
    p.add_argument("--experiment", required=True, metavar="EXP", help="experiment TOML file or shipped name")


def add_parsers(sub) -> None:
    """Add ``fit``, ``recover``, ``compare`` and ``sbi`` to the ``neurocur`` command's subparsers."""
    fit = _parser(
        sub, "fit",
        "fit a circuit's parameters to behaviour by maximum likelihood (docs/fitting.md)",
        "Replay each data set of DATA (a CSV or Parquet table with columns dataset, episode, context, "
        "decision; or a results folder, whose runs are the data sets) through the experiment condition's "
        "circuit and fit the --fit parameters by maximum likelihood, per data set and pooled, with 95 % "
        "profile-likelihood intervals (--ci bootstrap: parametric-bootstrap intervals per data set, none for "
        "the pooled fit, the replicates in OUT/bootstrap.csv). Writes OUT/fit.csv and OUT/summary.json.",
        "neurocur fit results/free_choice --experiment free_choice --condition learning_progress --fit LC.gain "
        "--bounds LC.gain=0:60 --signal HPC=error --out results/fit")
    _data(fit)
    _common(fit, keys_required=False)
    _intervals(fit)
    _trial_table(fit)
    recover = _parser(
        sub, "recover",
        "parameter (and model) recovery of an experiment's circuit (docs/fitting.md)",
        "Simulate --datasets data sets of --episodes episodes at parameters drawn uniformly within the bounds, "
        "fit each, and report r, bias and interval coverage per parameter; with --models, also fit every model "
        "to data sets simulated from each and report the confusion matrices.",
        "neurocur recover free_choice --condition learning_progress --fit LC.gain --bounds LC.gain=1:60 "
        "--signal HPC=error --datasets 20 --episodes 250")
    recover.add_argument("experiment", metavar="EXPERIMENT", help="experiment TOML file or shipped name")
    _common(recover, keys_required=False)
    _intervals(recover)
    recover.add_argument("--datasets", type=_count(3, "a number of data sets of at least 3 (Pearson r needs 3)"),
                         default=20, metavar="N", help="data sets (default 20; at least 3)")
    recover.add_argument("--episodes", type=_count(2, "a number of episodes of at least 2"), default=250, metavar="N",
                         help="episodes per data set (default 250)")
    recover.add_argument("--models", nargs="+", metavar="CONDITION",
                         help="model recovery among these conditions (each fitted on the --fit keys it has)")
    compare = _parser(
        sub, "compare",
        "compare models on behaviour: AIC, BIC, held-out and cross-validated log-likelihood, random-effects "
        "BMS (docs/fitting.md)",
        "Fit every --models condition to every data set of DATA (each on the --fit keys it has) and score it "
        "by AIC, BIC, the split-half held-out log-likelihood and leave-one-data-set-out cross-validation; "
        "random-effects Bayesian model selection on -BIC/2 gives each model's expected frequency and "
        "(protected) exceedance probability. Writes OUT/compare.csv, OUT/bms.csv and OUT/comparison.png.",
        "neurocur compare choices.csv --experiment free_choice --models learning_progress random --fit "
        "learning_progress:LC.gain --bounds LC.gain=0:60 --signal HPC=error --out results/compare")
    _data(compare)
    compare.add_argument("--models", nargs="+", required=True, metavar="CONDITION",
                         help="the conditions to compare, each fitted on the --fit keys it has (MODEL:KEY: in that "
                         "model only)")
    _common(compare, condition=False, keys_required=False)
    compare.add_argument("--no-loo", action="store_true",
                         help="skip the leave-one-data-set-out cross-validation (one pooled fit per data set)")
    _trial_table(compare)
    sbi = _parser(
        sub, "sbi",
        "simulation-based inference (neural posterior estimation) of parameters without a likelihood "
        "(docs/fitting.md)",
        "Simulate the experiment condition at --simulations / --runs prior draws, --runs runs each (an "
        "experiment per draw, with a seed of its own, run into OUT/sbi_training/: it resumes, and runs on Dask "
        "with --scheduler), train a neural posterior estimator on the choice sequences' summaries, and write "
        "the posterior median and 95 % interval of each data set of --data (OUT/sbi.csv); --test N checks it "
        "on N held-out simulations at prior draws, each with its own seed (OUT/sbi_recovery.csv, "
        "sbi_recovery_summary.csv, sbi_recovery.png). Needs the fit extra.",
        "neurocur sbi synthetic --condition curious --prior HPC.threshold=0.1:0.5 --simulations 200 --runs 5 "
        "--test 20 --out results/sbi")
    sbi.add_argument("experiment", metavar="EXPERIMENT", help="experiment TOML file or shipped name")
    sbi.add_argument("--condition", metavar="NAME", help="the condition to simulate (default: the first)")
    sbi.add_argument("--prior", action="append", required=True, metavar="KEY=LOW:HIGH",
                     help="a parameter to infer and its uniform prior (repeatable), e.g. HPC.threshold=0.1:0.5")
    sbi.add_argument("--simulations", type=int, required=True, metavar="N",
                     help="training simulations: prior draws x --runs")
    sbi.add_argument("--runs", type=int, default=5, metavar="R", help="runs at each prior draw (default 5)")
    sbi.add_argument("--steps", type=int, metavar="N", help="frames per run (default: the experiment's)")
    sbi.add_argument("--jobs", type=int, metavar="N", help="worker processes (default: all cores)")
    sbi.add_argument("--scheduler", metavar="ADDRESS", help="compute the runs on Dask: 'local' or tcp://HOST:PORT")
    sbi.add_argument("--seed", type=int, default=0, metavar="N", help="seed of the draws, runs and training (default 0)")
    sbi.add_argument("--data", metavar="DATA", help="a behaviour table (.csv, .parquet) or a results folder")
    sbi.add_argument("--test", type=int, default=0, metavar="N", help="held-out simulations to check on (default 0)")
    sbi.add_argument("--epochs", type=int, default=200, metavar="N", help="most training epochs (default 200)")
    sbi.add_argument("--out", metavar="DIR", help="output folder (default results/sbi-EXPERIMENT)")


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
    data, found = _checked_data(args, experiment, [condition], args.decision, args.signal)
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
        prior = dict(map(_bounds, args.prior))
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
    data, found = _checked_data(args, experiment, list(models.values()), args.decision, args.signal)
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
