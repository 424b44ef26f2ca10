"""The ``neurocur fit``, ``recover``, ``compare`` and ``sbi`` subcommands' parsers (:mod:`neurocur.cli` adds them).

Their options are checked here, before any folder is made (an integer below its least value is refused by
argparse in one line); the commands and what they write are :mod:`neurocur.fit.commands`'s, whose
``COMMANDS`` this module passes on.
"""

from __future__ import annotations

import argparse

from ..config.argtypes import int_at_least
from .commands import COMMANDS, parse_bounds
from .outdir import FitInterrupted

__all__ = ["COMMANDS", "FitInterrupted", "add_parsers"]


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
    p.add_argument("--bounds", action="append", type=parse_bounds, default=[], metavar="KEY=LOW:HIGH",
                   help="search range of a fitted parameter (default: its declared range, when finite)")
    p.add_argument("--signal", type=_signal, metavar="REGION=COLUMN",
                   help="signal replay: REGION emits the data's per-episode COLUMN instead of computing it")
    p.add_argument("--decision", default="LC", metavar="REGION", help="the decision region (default LC)")
    p.add_argument("--starts", type=int_at_least(1, "a number of optimiser starts of at least 1"), default=5, metavar="N",
                   help="optimiser starts per fit (default 5)")
    p.add_argument("--seed", type=int_at_least(0, "an integer >= 0"), default=0, metavar="N",
                   help="seed of the starts (default 0)")
    p.add_argument("--out", metavar="DIR", help="output folder")


_replicates = int_at_least(2, "a number of bootstrap replicates of at least 2")


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


def _hierarchical(p: argparse.ArgumentParser, what: str) -> None:
    """The hierarchical fit's options (:mod:`neurocur.fit.hierarchical`)."""
    p.add_argument("--hierarchical", action="store_true",
                   help=f"{what} by empirical-Bayes EM under a group prior fitted to all data sets (Huys et al. 2011; "
                   "at least 2 data sets)")
    p.add_argument("--em-iterations", type=int_at_least(1, "a number of E-steps of at least 1"), metavar="N",
                   help="with --hierarchical: the most E-steps of the EM (default 200); a fit that has not converged "
                   "by then is written with a warning")
    p.add_argument("--evidence-samples", type=int_at_least(2, "a number of samples of at least 2"), metavar="N",
                   help="with --hierarchical: draws from the group prior for the sampled evidence and iBIC (default "
                   "2000; each costs a likelihood per data set)")
    p.add_argument("--jobs", type=int_at_least(1, "a number of worker processes of at least 1"), metavar="N",
                   help="with --hierarchical: worker processes for the E-steps' data sets (default: all cores; the "
                   "results are the same for any N)")


def _parser(sub, name: str, help: str, description: str, example: str) -> argparse.ArgumentParser:
    """A subcommand's parser: its one-line ``help``, its ``description`` and one example after it."""
    return sub.add_parser(name, help=help, description=description, epilog=f"example:\n  {example}\n",
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def _data(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", metavar="DATA", help="a behaviour table (.csv, .parquet) or a results folder")
    p.add_argument("--experiment", required=True, metavar="EXP", help="experiment TOML file or shipped name")


def add_parsers(sub) -> None:
    """Add ``fit``, ``recover``, ``compare`` and ``sbi`` to the ``neurocur`` command's subparsers.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``neurocur`` parser's subparsers (what ``ArgumentParser.add_subparsers`` returns); each command's
        parser is added to it with its options.
    """
    fit = _parser(
        sub, "fit",
        "fit a circuit's parameters to behaviour by maximum likelihood (docs/fitting.md)",
        "Replay each data set of DATA (a CSV or Parquet table with columns dataset, episode, context, "
        "decision; or a results folder, whose runs are the data sets) through the experiment condition's "
        "circuit and fit the --fit parameters by maximum likelihood, per data set and pooled, with 95 % "
        "profile-likelihood intervals (--ci bootstrap: parametric-bootstrap intervals per data set, none for "
        "the pooled fit, the replicates in OUT/bootstrap.csv). Writes OUT/fit.csv and OUT/summary.json. With "
        "--hierarchical: each data set's MAP under a group prior fitted to all (fit.csv, with its Laplace "
        "interval; no pooled row), the group's parameters (OUT/group.csv) and its iBIC (summary.json).",
        "neurocur fit results/free_choice --experiment free_choice --condition learning_progress --fit LC.gain "
        "--bounds LC.gain=0:60 --signal HPC=error --out results/fit")
    _data(fit)
    _common(fit, keys_required=False)
    _intervals(fit)
    _trial_table(fit)
    _hierarchical(fit, "fit each data set")
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
    recover.add_argument("--datasets", type=int_at_least(3, "a number of data sets of at least 3 (Pearson r needs 3)"),
                         default=20, metavar="N", help="data sets (default 20; at least 3)")
    recover.add_argument("--episodes", type=int_at_least(2, "a number of episodes of at least 2"), default=250, metavar="N",
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
        "(protected) exceedance probability. Writes OUT/compare.csv, OUT/bms.csv and OUT/comparison.png. With "
        "--hierarchical: every model fitted hierarchically, ranked by iBIC (OUT/hierarchical.csv), BMS on each data "
        "set's Laplace log evidence under the model's group prior (OUT/compare.csv, OUT/bms.csv; no figure).",
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
    _hierarchical(compare, "fit every model")
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
    sbi.add_argument("--simulations", type=int_at_least(1, "a number of simulations of at least 1"), required=True, metavar="N",
                     help="training simulations: prior draws x --runs")
    sbi.add_argument("--runs", type=int_at_least(1, "a number of runs of at least 1"), default=5, metavar="R", help="runs at each prior draw (default 5)")
    sbi.add_argument("--steps", type=int_at_least(1, "a number of frames of at least 1"), metavar="N", help="frames per run (default: the experiment's)")
    sbi.add_argument("--jobs", type=int_at_least(1, "a number of workers of at least 1"), metavar="N", help="worker processes (default: all cores)")
    sbi.add_argument("--scheduler", metavar="ADDRESS", help="compute the runs on Dask: 'local' or tcp://HOST:PORT")
    sbi.add_argument("--seed", type=int_at_least(0, "an integer >= 0"), default=0, metavar="N", help="seed of the draws, runs and training (default 0)")
    sbi.add_argument("--data", metavar="DATA", help="a behaviour table (.csv, .parquet) or a results folder")
    sbi.add_argument("--test", type=int_at_least(0, "a number of held-out simulations >= 0"), default=0, metavar="N", help="held-out simulations to check on (default 0)")
    sbi.add_argument("--epochs", type=int_at_least(1, "a number of epochs of at least 1"), default=200, metavar="N", help="most training epochs (default 200)")
    sbi.add_argument("--out", metavar="DIR", help="output folder (default results/sbi-EXPERIMENT)")
