"""The ``neurocur`` command: run experiments, draw their figures, measure Ω, show invariance.

A thin layer: it parses arguments and calls :mod:`neurocur.experiments`,
:mod:`neurocur.analysis` (and :mod:`neurocur.experiments.invariance`) and
:mod:`neurocur.learn.omega`.
Every user-facing error (arguments, configuration, a results folder that cannot be
written or resumed, unreadable files) is printed as one line naming what was wrong and
what was expected, with exit status 2. Ctrl-C exits with status 130 (a fit command says what its
output folder holds).
"""

from __future__ import annotations

import argparse
import gc
import os
import signal
import sys
import threading
from pathlib import Path
from typing import NoReturn

import numpy as np

from neurocur.config.argtypes import int_at_least, mca_eta, memory_size
from neurocur.config.helpformat import HelpFormatter

EPILOG = """\
examples:
  neurocur run synthetic                     the paper's synthetic experiment (25 runs x 3.5e5 steps)
  neurocur run synthetic --runs 4 --steps 50000 --jobs 2 --out results/quick
  neurocur run synthetic --condition curious --set HPC.threshold=0.25 world.normalise=image
  neurocur run my_experiment.toml            an experiment file of your own (a path)
  neurocur figures results/synthetic         write the figures into results/synthetic/figures/
  neurocur omega source.npy --eta 0.05       learning cost of a signal (rows are time)
  neurocur omega --experiment synthetic      Omega of every context's frames
  neurocur invariance invariance             Figure 5: invariance of a learned slow feature

EXPERIMENT is a path, or the name of an experiment shipped in the package
(neurocur/experiments_data/NAME.toml); 'neurocur list' shows them all, one line each.

Running again into the same results folder resumes: finished runs are kept. One process at a
time writes into a results folder; resuming refuses changed input files and (unless
--accept-code-change) changed code. Ctrl-C finishes the runs in progress; twice abandons them.
"""


_positive_int = int_at_least(1, "a positive integer")
_seed = int_at_least(0, "an integer >= 0")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="neurocur",
        description="Curiosity-driven modular incremental slow feature analysis (CD-MISFA): "
        "run experiments, draw their figures, measure learning cost.",
        epilog=EPILOG,
        formatter_class=HelpFormatter,
    )
    from neurocur import __version__

    parser.add_argument("--version", action="version", version=f"neurocur {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    run = sub.add_parser(
        "run", help="run an experiment file into a results folder",
        description="Run every condition x run of an experiment file in worker processes. Each run is written "
        "to OUT/runs/<condition>/run-<NNN>/ as soon as it finishes; running again into the same folder skips "
        "finished runs. At the end a table of module orders is printed.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("experiment", metavar="EXPERIMENT", help="experiment TOML file or shipped name (e.g. synthetic)")
    run.add_argument("--runs", type=_positive_int, metavar="N", help="number of runs per condition (overrides the file)")
    run.add_argument("--steps", type=_positive_int, metavar="N", help="frames per run (overrides the file)")
    run.add_argument("--seed", type=_seed, metavar="N",
                     help="root seed of the runs (overrides the file; run i of every condition gets the same child)")
    run.add_argument("--jobs", type=_positive_int, metavar="N",
                     help="worker processes (default: all cores; with --scheduler local, the Dask workers)")
    run.add_argument("--scheduler", metavar="ADDRESS",
                     help="compute the runs on Dask: 'local' (a LocalCluster on this machine) or a scheduler's "
                     "address, tcp://HOST:PORT (docs/cluster.md); default: local worker processes")
    run.add_argument("--out", metavar="DIR", help="results folder (default: results/<experiment name>)")
    run.add_argument("--condition", action="append", metavar="NAME",
                     help="run only this condition (repeatable; default: all)")
    run.add_argument("--set", dest="sets", action="extend", nargs="+", default=[], metavar="KEY=VALUE",
                     help="override a setting: runs, steps, seed, circuit, world.KEY or REGION.param; "
                     "VALUE is a TOML literal (0.3, true, [1, 2], \"text\"; a bare word is a string)")
    run.add_argument("--max-memory", type=memory_size, metavar="SIZE",
                     help="memory the workers may use together, e.g. 8G (default: what the machine has available); "
                     "estimated from each condition's first episode before any worker starts")
    run.add_argument("--checkpoint-every", type=int_at_least(0, "an integer >= 0"), metavar="N",
                     help="save each run's state every N episodes into OUT/checkpoints/, so that a stopped run "
                     "continues from there (0: never; default: every 200 episodes for runs of 200000 steps or more)")
    run.add_argument("--save-agent", action="store_true",
                     help="write each run's trained agent into its run folder (agent/; neurocur.load_agent reads it)")
    run.add_argument("--accept-code-change", action="store_true",
                     help="resume into a folder whose runs other code computed (the folder records every code "
                     "version that wrote runs into it); changed input files are always refused")
    bar = run.add_mutually_exclusive_group()
    bar.add_argument("--progress", dest="progress", action="store_true", default=None,
                     help="always show the progress bar (default: only on a terminal)")
    bar.add_argument("--no-progress", dest="progress", action="store_false", help="never show the progress bar")

    figures = sub.add_parser(
        "figures", help="draw the figures of a results folder",
        description="Draw every figure of a results folder (paper Figures 4D-G and the order counts) as PNG.")
    figures.add_argument("results", metavar="RESULTS_DIR", help="a results folder written by 'neurocur run'")
    figures.add_argument("--out", metavar="DIR", help="where to write the PNGs (default: RESULTS_DIR/figures)")
    figures.add_argument("--no-invariance", dest="invariance", action="store_false",
                         help="a synthetic world's folder: do not run the invariance demo for Figure 5 (4 s)")

    omega = sub.add_parser(
        "omega", help="learning cost Omega of a signal or of a context's frames (eq 15)",
        description="Omega = 1 - eta (lambda_{n-1} - lambda_n) / (1 - eta - eta lambda_n) (paper eqs 15, 40): "
        "lower is cheaper to learn, 1 is never learned. Give a .npy file (rows are time), or an experiment "
        "(and optionally a context) to measure the frames of its world. A synthetic context whose source is "
        "redrawn every epoch (S-D, noise, re-sampled sources) is measured on --draws fresh draws: Omega of the "
        "draws joined (no derivative across a redraw), then each draw's mean and range. An episodic (iCub) "
        "context is measured after a PCA to 98 % of the variance (no derivative across episodes), and the "
        "dimensions it keeps are printed.",
        epilog="examples:\n  neurocur omega signal.npy\n  neurocur omega --experiment synthetic "
        "--context C3\n", formatter_class=argparse.RawDescriptionHelpFormatter)
    omega.add_argument("file", metavar="FILE.npy", nargs="?", help="a (time, dims) array saved with numpy.save")
    omega.add_argument("--experiment", metavar="FILE", help="experiment TOML (or shipped name) whose world's contexts to measure")
    omega.add_argument("--context", metavar="NAME", help="context name (e.g. C3); default: every context")
    omega.add_argument("--condition", metavar="NAME", help="condition whose world to use (default: the first)")
    omega.add_argument("--seed", type=int, default=0, help="world seed (mixing matrices, S-D, draws of redrawn sources; default 0)")
    omega.add_argument("--set", dest="sets", action="extend", nargs="+", default=[], metavar="KEY=VALUE",
                       help="override a setting of the experiment, e.g. world.normalise=image")
    omega.add_argument("--eta", type=mca_eta, default=0.05, help="MCA learning rate (default 0.05)")
    omega.add_argument("--draws", type=_positive_int, default=10,
                       help="draws of a source redrawn every epoch (default 10)")

    invariance = sub.add_parser(
        "invariance", help="Figure 5: a learned slow feature is invariant to the other source dimension",
        description="Train IncSFA on one source's frames, replace the source's second dimension by noise and "
        "compare the first feature's output before and after (section 4.1.5). Writes OUT/invariance.png "
        "(Figure 5 A-F) and OUT/invariance.json (the settings, corr and quality).",
        epilog="example:\n  neurocur invariance invariance --out results/fig5\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    invariance.add_argument("experiment", metavar="EXPERIMENT", help="invariance TOML file or shipped name (invariance)")
    invariance.add_argument("--out", metavar="DIR", help="output folder (default: results/<name in the file>)")

    sub.add_parser("list", help="the shipped experiments and circuits, one line each",
                   description="List the experiments, invariance demonstrations and circuits shipped in the package.")
    from neurocur.fit.cli import add_parsers as add_fit_parsers

    add_fit_parsers(sub)  # fit, recover
    completion = sub.add_parser(
        "completion", help="print the shell completion script (bash or zsh)",
        description="Print the completion script of the neurocur command for the shell (made by shtab).",
        epilog="examples:\n  neurocur completion bash > ~/.local/share/bash-completion/completions/neurocur\n"
        "  neurocur completion zsh > ~/.zfunc/_neurocur      (a folder of your fpath)\n")
    completion.add_argument("shell", choices=("bash", "zsh"), help="the shell")
    for subparser in sub.choices.values():  # every subcommand's help fits HELP_WIDTH, the fit layer's too
        subparser.formatter_class = HelpFormatter
    return parser


def _cmd_run(args) -> int:
    from neurocur.experiments.executors import executor_for

    executor = executor_for(args.scheduler, args.jobs)
    executor.start()  # the local workers' fork server imports the model while this process does too
    from neurocur.experiments import load_experiment, run_experiment

    exp = load_experiment(args.experiment, sets=args.sets, runs=args.runs, steps=args.steps, seed=args.seed)
    out = Path(args.out) if args.out else Path("results") / exp.name
    tables = None

    def summarise(folder: Path) -> None:  # under the folder's lock, once the runs are done
        from neurocur.analysis import write_summary
        from neurocur.results import ResultsStore

        nonlocal tables
        tables = ResultsStore(folder).load()
        write_summary(folder, tables=tables)
        if any(condition.world_class.figures_after_run for condition in exp.conditions.values()):
            from neurocur.analysis.figures import write_all  # a small task's figures (docs/validation.md)

            for path in write_all(folder):
                print(path)

    run_experiment(exp, out, conditions=args.condition, progress=args.progress, max_memory=args.max_memory,
                   accept_code_change=args.accept_code_change, executor=executor, finish=summarise,
                   checkpoint_every=args.checkpoint_every, save_agent=args.save_agent)
    from neurocur.analysis import narrow, order_tables, verdict_text

    print(f"results: {out}")
    from neurocur.analysis.figures.sets import task_report

    report = task_report(out, tables=tables)
    if report is not None:  # a canonical task: its own statistics, not the module-learning summary
        from neurocur.analysis.stats.validation import over_runs_text

        print(over_runs_text(report))
    else:
        print(narrow(order_tables(out, conditions=list(exp.conditions), tables=tables)))
        print(verdict_text(out, conditions=list(exp.conditions), tables=tables))
    return 0


def _cmd_figures(args) -> int:
    from neurocur.analysis.figures.sets import FIGURE_5, write_figures

    if args.out is not None:
        _check_writable_folder(Path(args.out), "--out")
    paths, notes = write_figures(args.results, args.out, also=_figure_5 if args.invariance else None)
    drawn = any(path.name == "invariance.png" for path in paths)
    for line in [*map(str, paths), *(note for note in notes if not (drawn and note == FIGURE_5))]:
        print(line)
    return 0


def _figure_5(results, out: Path) -> dict:
    """Figure 5 for a synthetic world's folder: the shipped invariance demo (``neurocur invariance invariance``,
    seeded) run into ``out``, its ``invariance.json`` beside the figure; nothing for another world."""
    if results.world_types != {"synthetic"}:
        return {}
    from neurocur.analysis.figures.invariance import fig_invariance
    from neurocur.experiments.invariance import load_invariance, write_invariance

    spec = load_invariance("invariance")
    demo, _ = write_invariance(spec, out)
    return {"invariance": fig_invariance(demo)}


def _cmd_omega(args) -> int:
    from neurocur.config.npy import load_npy
    from neurocur.learn.omega import omega

    if (args.file is None) == (args.experiment is None):
        raise ValueError("omega: give either FILE.npy or --experiment FILE (not both)")
    if args.file is not None:
        if args.context or args.condition or args.sets:
            raise ValueError("omega: --context, --condition and --set need --experiment, not FILE.npy")
        path = Path(args.file)
        if not path.is_file():
            raise ValueError(f"omega: FILE.npy: expected an existing .npy file, got {str(path)!r} (no such file)")
        try:
            X = load_npy(path)
        except (ValueError, OSError, EOFError) as exc:
            raise ValueError(f"omega: {path}: {exc}") from None
        if X.dtype.kind in "fiu":
            with np.errstate(over="ignore", invalid="ignore"):
                if not np.isfinite(np.var(X, axis=0, dtype=np.float64)).all():
                    raise ValueError(f"omega: {path}: expected a signal whose variance is finite in float64 "
                                     f"(|x| up to about 1e150), got values up to {np.nanmax(np.abs(X)):.3g}")
        try:
            value = omega(X, args.eta)
        except ValueError as exc:
            raise ValueError(f"omega: {path}: {exc}") from None
        print(f"{path}: Omega = {value:.5f}  (eta = {args.eta:g}, {X.shape[0]} steps)")
        return 0
    import pandas as pd

    from neurocur.contexts.learnability import learnability
    from neurocur.experiments import load_experiment

    exp = load_experiment(args.experiment, sets=args.sets)
    condition = exp.select([args.condition] if args.condition else None)[0]
    world = condition.make_world()
    world.reset(seed=args.seed)
    if args.context is not None and args.context not in world.context_names:
        raise ValueError(f"omega: --context: expected one of {', '.join(world.context_names)}, got {args.context!r}")
    table = learnability(world, args.eta, draws=args.draws, seed=args.seed,
                         contexts=None if args.context is None else [args.context])
    for row in table.itertuples(index=False):
        redrawn = (f"  redrawn every epoch: {args.draws} draws joined; per draw mean {row.omega_draw_mean:.5f}, "
                   f"range [{row.omega_draw_min:.5f}, {row.omega_draw_max:.5f}]") if row.redrawn else ""
        dims = "" if pd.isna(row.pca_dims) else f"  (PCA to 98 % of the variance: {row.pca_dims} dims)"
        print(f"{row.context_name}  {row.source:<6} Omega = {row.omega:.5f}{dims}{redrawn}")
    return 0


def _cmd_invariance(args) -> int:
    from neurocur.analysis.figures.invariance import save_invariance
    from neurocur.experiments.invariance import load_invariance, write_invariance

    spec = load_invariance(args.experiment)
    out = Path(args.out) if args.out else Path("results") / spec.name
    demo, result = write_invariance(spec, out)
    print(f"{spec.source}: corr = {demo.corr:.5f} (first feature before/after the swap), "
          f"quality = {demo.quality:.5f} (|corr| with the slow source dimension)")
    for path in (save_invariance(demo, out), result):
        print(path)
    return 0


def _cmd_list(args) -> int:
    from neurocur.experiments.catalog import format_catalog

    print(format_catalog())
    return 0


def _cmd_completion(args) -> int:
    import shtab

    parser = build_parser()
    for action in (a for p in [parser, *parser._subparsers._group_actions[0].choices.values()] for a in p._actions):
        if action.metavar in ("EXPERIMENT", "EXP", "FILE", "FILE.npy", "DATA"):
            action.complete = shtab.FILE
        elif action.metavar in ("DIR", "RESULTS_DIR"):
            action.complete = shtab.DIRECTORY
    print(shtab.complete(parser, shell=args.shell))
    return 0


def _check_writable_folder(path: Path, option: str) -> None:
    """ValueError unless ``path`` is a folder this process can write into, or can be created as one."""
    if path.exists() and not path.is_dir():
        raise ValueError(f"{option}: expected a folder, got {str(path)!r} (a file)")
    existing = next(p for p in (path, *path.absolute().parents) if p.exists())
    if not existing.is_dir():
        raise ValueError(f"{option}: expected a folder, got {str(path)!r} (inside the file {str(existing)!r})")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"{option}: expected a folder you can write into, got {str(path)!r} "
                         f"({str(existing)!r} is not writable)")


def main(argv=None) -> int:
    """Entry point of the ``neurocur`` command; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    from neurocur.fit.cli import COMMANDS as FIT_COMMANDS

    command = {"run": _cmd_run, "figures": _cmd_figures, "omega": _cmd_omega,
               "invariance": _cmd_invariance, "list": _cmd_list, "completion": _cmd_completion,
               **FIT_COMMANDS}[args.command]
    try:
        return command(args)
    except (ValueError, OSError) as exc:  # ConfigError is a ValueError; OSError: a file that cannot be read or written
        print(f"neurocur {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"neurocur {args.command}: error: out of memory: a setting asks for more memory than this process may "
              "allocate (e.g. world.frame_shape, steps, a source file); use smaller settings", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # a further Ctrl-C must not interrupt the exit
        from neurocur.experiments.runner import Interrupted
        from neurocur.fit.cli import FitInterrupted

        if isinstance(exc, FitInterrupted):  # a fit command: what its output folder holds
            print(f"neurocur {args.command}: interrupted; {exc}", file=sys.stderr)
        elif not isinstance(exc, Interrupted):  # else the runner has said what happened
            print("neurocur: interrupted; finished runs are kept (run again to resume)", file=sys.stderr)
        return 130


def command() -> NoReturn:
    """The ``neurocur`` console script: :func:`main`, then exit with its status.

    The objects still alive are frozen first (:func:`gc.freeze`), so that the interpreter's
    final garbage collections skip them: with the model imported (numpy, pandas, numba,
    scikit-learn) they took 0.3-0.5 s of every command's exit. Only the console script does
    this; ``main`` called from Python leaves the collector alone."""
    status = main()
    gc.freeze()
    sys.exit(status)


if __name__ == "__main__":
    command()
