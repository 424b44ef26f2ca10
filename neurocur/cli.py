"""The ``neurocur`` command: run experiments, draw their figures, measure Ω, show invariance.

A thin layer: it parses arguments and calls :mod:`neurocur.experiments`,
:mod:`neurocur.analysis` (and :mod:`neurocur.analysis.invariance`) and
:mod:`neurocur.learn.omega`.
Errors in arguments or configuration are printed as one line naming the key and
what was expected, with exit status 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

EPILOG = """\
examples:
  neurocur run experiments/synthetic.toml                  the paper's synthetic experiment (25 runs x 3.5e5 steps)
  neurocur run experiments/synthetic.toml --runs 4 --steps 50000 --jobs 2 --out results/quick
  neurocur run experiments/synthetic.toml --condition curious --set HPC.threshold=0.25 world.normalise=image
  neurocur figures results/synthetic                       write the figures into results/synthetic/figures/
  neurocur omega source.npy --eta 0.05                     learning cost of a signal (rows are time)
  neurocur omega --experiment experiments/synthetic.toml   Omega of every context's frames
  neurocur invariance experiments/invariance.toml          Figure 5: invariance of a learned slow feature

Running again into the same results folder resumes: finished runs are kept.
"""


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def _eta(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number in (0, 0.5], got {text!r}") from None
    if not 0.0 < value <= 0.5:
        raise argparse.ArgumentTypeError(f"expected a number in (0, 0.5], got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="neurocur",
        description="Curiosity-driven modular incremental slow feature analysis (CD-MISFA): "
        "run experiments, draw their figures, measure learning cost.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
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
    run.add_argument("experiment", metavar="EXPERIMENT", help="experiment TOML file (e.g. experiments/synthetic.toml)")
    run.add_argument("--runs", type=_positive_int, metavar="N", help="number of runs per condition (overrides the file)")
    run.add_argument("--steps", type=_positive_int, metavar="N", help="frames per run (overrides the file)")
    run.add_argument("--seed", type=_seed, metavar="N",
                     help="root seed of the runs (overrides the file; run i of every condition gets the same child)")
    run.add_argument("--jobs", type=_positive_int, metavar="N", help="worker processes (default: all cores)")
    run.add_argument("--out", metavar="DIR", help="results folder (default: results/<experiment name>)")
    run.add_argument("--condition", action="append", metavar="NAME",
                     help="run only this condition (repeatable; default: all)")
    run.add_argument("--set", dest="sets", action="extend", nargs="+", default=[], metavar="KEY=VALUE",
                     help="override a setting: runs, steps, seed, circuit, world.KEY or REGION.param; "
                     "VALUE is a TOML literal (0.3, true, [1, 2], \"text\"; a bare word is a string)")
    bar = run.add_mutually_exclusive_group()
    bar.add_argument("--progress", dest="progress", action="store_true", default=None,
                     help="always show the progress bar (default: only on a terminal)")
    bar.add_argument("--no-progress", dest="progress", action="store_false", help="never show the progress bar")

    figures = sub.add_parser(
        "figures", help="draw the figures of a results folder",
        description="Draw every figure of a results folder (paper Figures 4D-G and the order counts) as PNG.")
    figures.add_argument("results", metavar="RESULTS_DIR", help="a results folder written by 'neurocur run'")
    figures.add_argument("--out", metavar="DIR", help="where to write the PNGs (default: RESULTS_DIR/figures)")

    omega = sub.add_parser(
        "omega", help="learning cost Omega of a signal or of a context's frames (eq 15)",
        description="Omega = 1 - eta (lambda_{n-1} - lambda_n) / (1 - eta - eta lambda_n) (paper eqs 15, 40): "
        "lower is cheaper to learn, 1 is never learned. Give a .npy file (rows are time), or an experiment "
        "(and optionally a context) to measure the frames of its world.",
        epilog="examples:\n  neurocur omega signal.npy\n  neurocur omega --experiment experiments/synthetic.toml "
        "--context C3\n", formatter_class=argparse.RawDescriptionHelpFormatter)
    omega.add_argument("file", metavar="FILE.npy", nargs="?", help="a (time, dims) array saved with numpy.save")
    omega.add_argument("--experiment", metavar="FILE", help="experiment TOML whose world's contexts to measure")
    omega.add_argument("--context", metavar="NAME", help="context name (e.g. C3); default: every context")
    omega.add_argument("--condition", metavar="NAME", help="condition whose world to use (default: the first)")
    omega.add_argument("--seed", type=int, default=0, help="world seed (mixing matrices, S-D; default 0)")
    omega.add_argument("--set", dest="sets", action="extend", nargs="+", default=[], metavar="KEY=VALUE",
                       help="override a setting of the experiment, e.g. world.normalise=image")
    omega.add_argument("--eta", type=_eta, default=0.05, help="MCA learning rate (default 0.05)")

    invariance = sub.add_parser(
        "invariance", help="Figure 5: a learned slow feature is invariant to the other source dimension",
        description="Train IncSFA on one source's frames, replace the source's second dimension by noise and "
        "compare the first feature's output before and after (section 4.1.5). Writes OUT/invariance.png "
        "(Figure 5 A-F) and OUT/invariance.json (the settings, corr and quality).",
        epilog="example:\n  neurocur invariance experiments/invariance.toml --out results/fig5\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    invariance.add_argument("experiment", metavar="EXPERIMENT", help="invariance TOML file (experiments/invariance.toml)")
    invariance.add_argument("--out", metavar="DIR", help="output folder (default: results/<name in the file>)")
    return parser


def _cmd_run(args) -> int:
    import pandas as pd

    from neurocur.analysis import order_tables, write_summary
    from neurocur.experiments import load_experiment, run_experiment

    exp = load_experiment(args.experiment, sets=args.sets, runs=args.runs, steps=args.steps, seed=args.seed)
    out = Path(args.out) if args.out else Path("results") / exp.name
    run_experiment(exp, out, jobs=args.jobs, conditions=args.condition, progress=args.progress)
    write_summary(out)
    print(f"results: {out}")
    with pd.option_context("display.width", 200, "display.max_columns", None):
        print(order_tables(out, conditions=list(exp.conditions)).to_string())
    return 0


def _cmd_figures(args) -> int:
    from neurocur.analysis.figures import write_all

    for path in write_all(args.results, args.out):
        print(path)
    return 0


def _cmd_omega(args) -> int:
    from neurocur.learn.omega import omega

    if (args.file is None) == (args.experiment is None):
        raise ValueError("omega: give either FILE.npy or --experiment FILE (not both)")
    if args.file is not None:
        if args.context or args.condition or args.sets:
            raise ValueError("omega: --context, --condition and --set need --experiment, not FILE.npy")
        path = Path(args.file)
        if not path.is_file():
            raise ValueError(f"omega: FILE.npy: expected an existing .npy file, got {str(path)!r} (no such file)")
        X = np.load(path, allow_pickle=False)
        print(f"{path}: Omega = {omega(X, args.eta):.5f}  (eta = {args.eta:g}, {X.shape[0]} steps)")
        return 0
    from neurocur.experiments import load_experiment

    exp = load_experiment(args.experiment, sets=args.sets)
    condition = exp.select([args.condition] if args.condition else None)[0]
    world = condition.make_world()
    world.reset(seed=args.seed)
    contexts = list(world.context_names) if args.context is None else [args.context]
    for name in contexts:
        if name not in world.context_names:
            raise ValueError(f"omega: --context: expected one of {', '.join(world.context_names)}, got {name!r}")
        index = world.context_names.index(name)
        if hasattr(world, "context_frames"):  # a synthetic world: one frame sequence per context
            value = omega(world.context_frames(name), args.eta)
        else:  # an episodic world (iCub): derivatives within episodes only
            from neurocur.contexts.icub import omega_episodes

            value = omega_episodes(world.episodes(index), args.eta)
        print(f"{name}  {world.source_names[index]:<6} Omega = {value:.5f}")
    return 0


def _cmd_invariance(args) -> int:
    from neurocur.analysis.invariance import load_invariance, write_invariance

    spec = load_invariance(args.experiment)
    out = Path(args.out) if args.out else Path("results") / spec.name
    demo, paths = write_invariance(spec, out)
    print(f"{spec.source}: corr = {demo.corr:.5f} (first feature before/after the swap), "
          f"quality = {demo.quality:.5f} (|corr| with the slow source dimension)")
    for path in paths:
        print(path)
    return 0


def main(argv=None) -> int:
    """Entry point of the ``neurocur`` command; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    command = {"run": _cmd_run, "figures": _cmd_figures, "omega": _cmd_omega,
               "invariance": _cmd_invariance}[args.command]
    try:
        return command(args)
    except ValueError as exc:  # ConfigError is a ValueError: one line naming the key, no traceback
        print(f"neurocur {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("neurocur: interrupted; finished runs are kept (run again to resume)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
