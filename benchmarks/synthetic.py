"""Wall time, peak memory and a per-component profile of the synthetic experiment (a script, not a test).

    python benchmarks/synthetic.py                          # 25 runs x 3.5e5 frames of 'curious', all cores
    python benchmarks/synthetic.py --runs 4 --steps 50000 --condition random_switching --jobs 2

1. The sweep: ``neurocur run synthetic`` for one condition, in a
   child process, into a temporary folder (deleted afterwards), twice. The first is timed
   with nothing watching it: wall time, seconds per run. The second is watched for memory:
   the peak resident memory (VmHWM) of the command's process and of
   its largest worker, and the largest summed resident memory of all of them at
   once (sampled from /proc every 0.1 s; Linux), plus ``getrusage(RUSAGE_CHILDREN)``.
   The watching is not free: reading a worker's ``smaps_rollup`` walks its page tables,
   and one sample of the command's processes took about 44 ms, a sixth of a core taken from
   two busy workers, which made the sweep 1.5-2 s slower; so its wall time is printed beside
   the timed one but is not the figure. The two sweeps' order tables must be identical (same
   seeds), which the script checks.
   Workers are started by a forkserver, so they are the command's grandchildren:
   their usage reaches RUSAGE_CHILDREN only through the forkserver, which is why the
   /proc sampling is the figure to read. A worker's resident size counts the pages of the
   modules the forkserver imported before forking (numpy, pandas, numba, scikit-learn:
   about 230 MB), which every worker shares; its proportional set size (PSS) counts a
   shared page in proportion to the processes sharing it, and its unique set size (USS)
   only its private pages, the memory one more worker adds. The fork server (and
   multiprocessing's resource tracker) are not workers and are left out of the workers'
   figures: the server's resident size is reported on its own, and once the workers have
   ended every page it holds is its own again, so counted as a worker it showed a USS
   equal to its RSS at the end of some sweeps and not others.
   From the wall time: seconds per run per core (wall x jobs / runs) and runs per
   core-hour (3600 / that). From each run's own time (its ``run.json``) and when it was
   written: where the wall goes (start-up before the first run, the runs, what follows the
   last), and a run's time in its worker apart from each worker's first: the cost per run of a
   sweep long enough that its fixed start and end no longer count.
2. IncSFA alone: ``IncSFA.partial_fit`` on the same number of frames, in visits of 100
   frames of one paper source (S-A) with the experiment's EC parameters, in this
   process (single-threaded, as the workers are); the ratio of a run's seconds per core to it is what the rest of the model
   costs on top of learning the features.
3. The core: one run of the condition in this process without a profiler, its seconds, and
   of them the compiled IncSFA kernel (``_kernels.incsfa_fit``) and the EC's encoding (the
   matrix products of ``ECIncSFA.step``), timed call by call: the arithmetic a run must do
   whatever the Python around it costs. Beside it, the seconds per run that the target
   (25 runs with 2 jobs in 15 s wall) leaves: 15 s over the runs one worker does in turn.
4. The breakdown: one run of the condition in this process under cProfile (after a
   short warm-up run, so numba's compilation is not counted), the cumulative time of
   the learners and of the world, and the rest (regions' own code, the scheduler,
   recording, tables).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import resource
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

EXPERIMENT = Path(__file__).resolve().parents[1] / "neurocur" / "experiments_data" / "synthetic.toml"
#: the wall-time target of the paper-size condition (25 runs, 2 jobs), in seconds
TARGET_WALL = 15.0
#: One BLAS/numba thread in this process too, as in the workers (neurocur.experiments.processes): set before
#: numpy is imported; a second BLAS thread spinning on a busy machine would slow every matrix product.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

#: (label, file suffix, function name): top-level calls whose cumulative times do not nest.
COMPONENTS = (
    ("IncSFA partial_fit (EC learn)", "neurocur/learn/incsfa.py", "partial_fit"),
    ("ROC episode_error (HPC step)", "neurocur/learn/roc.py", "episode_error"),
    ("ROC partial_fit (HPC learn)", "neurocur/learn/roc.py", "partial_fit"),
    ("ROC prune (storage)", "neurocur/learn/roc.py", "prune"),
    ("LSPI solve (PFC step)", "neurocur/learn/lspi.py", "solve"),
    ("world: a visit (sensory step)", "neurocur/contexts/base.py", "step"),
    ("world: a stay's visits (sensory step)", "neurocur/contexts/base.py", "visits"),
    ("EC encoding: matrix products (EC step)", "neurocur/regions/ec.py", "step"),
    ("tables: episodes(), modules()", "neurocur/scheduler.py", "episodes"),
)


class MemorySampler(threading.Thread):
    """Samples VmHWM / VmRSS (kB) of a process and all its descendants from /proc."""

    def __init__(self, root_pid: int, interval: float = 0.1):
        super().__init__(daemon=True)
        self.root, self.interval = root_pid, interval
        self.hwm: dict[int, int] = {}
        self.pss: dict[int, int] = {}
        self.uss: dict[int, int] = {}
        self.peak_total = 0
        self.helpers: dict[int, str] = {}  # the fork server and the resource tracker: not workers
        self.parent: dict[int, int] = {}
        self._halt = threading.Event()

    def run(self) -> None:
        while not self._halt.is_set():
            self.sample()
            self._halt.wait(self.interval)

    def stop(self) -> None:
        self._halt.set()
        self.join()

    def sample(self) -> None:
        status = {}
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    text = Path(f"/proc/{entry}/status").read_text()
                except OSError:
                    continue
                fields = dict(line.split(":", 1) for line in text.splitlines() if ":" in line)
                status[int(entry)] = fields
        family, frontier = set(), {self.root}
        while frontier:
            family |= frontier
            frontier = {pid for pid, f in status.items() if int(f.get("PPid", "0")) in frontier} - family
        total = 0
        for pid in family & status.keys():
            fields = status[pid]
            role = _helper_role(pid) if int(fields.get("PPid", "0")) == self.root else ""
            if role:
                self.helpers[pid] = role
            if "VmHWM" in fields:
                self.parent[pid] = int(fields.get("PPid", "0"))
                self.hwm[pid] = max(self.hwm.get(pid, 0), int(fields["VmHWM"].split()[0]))
                total += int(fields["VmRSS"].split()[0])
                pss, uss = _proportional_and_unique(pid)
                self.pss[pid] = max(self.pss.get(pid, 0), pss)
                self.uss[pid] = max(self.uss.get(pid, 0), uss)
        self.peak_total = max(self.peak_total, total)


def _helper_role(pid: int) -> str:
    """``"fork server"`` or ``"resource tracker"`` for multiprocessing's helper processes (children
    of the command; the workers the fork server forks carry its command line too), else ``""``.
    The fork server is no worker: its pages are the ones workers share, and once the workers have
    ended they are all its own (its USS then equals its RSS)."""
    try:
        cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().decode(errors="replace")
    except OSError:
        return ""
    for module, role in (("multiprocessing.forkserver", "fork server"), ("multiprocessing.resource_tracker",
                                                                       "resource tracker")):
        if module in cmdline:
            return role
    return ""


def _proportional_and_unique(pid: int) -> tuple[int, int]:
    """Proportional set size (kB: the process's private pages plus its share of the pages it shares)
    and unique set size (kB: its private pages only, what ending it would free)."""
    try:
        text = Path(f"/proc/{pid}/smaps_rollup").read_text()
    except OSError:
        return 0, 0
    kb = {line.split(":")[0]: int(line.split()[1]) for line in text.splitlines()[1:] if line.endswith("kB")}
    return kb.get("Pss", 0), kb.get("Private_Clean", 0) + kb.get("Private_Dirty", 0)


def sweep(runs: int, steps: int, condition: str, jobs: int, *, watched: bool) -> dict:
    """One ``neurocur run`` of the condition: its wall time, output and timeline (:func:`run_timeline`),
    and with ``watched`` its processes' memory, sampled while it runs (which slows it)."""
    with tempfile.TemporaryDirectory(prefix="neurocur-bench-") as out:
        argv = [sys.executable, "-m", "neurocur.cli", "run", str(EXPERIMENT), "--runs", str(runs), "--steps",
                str(steps), "--jobs", str(jobs), "--condition", condition, "--out", out, "--no-progress"]
        start, started = time.perf_counter(), time.time()
        child = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if watched:
            sampler = MemorySampler(child.pid)
            sampler.start()
        output, _ = child.communicate()
        wall = time.perf_counter() - start
        if watched:
            sampler.stop()
        if child.returncode != 0:
            raise SystemExit(f"neurocur run failed (exit {child.returncode}):\n{output}")
        timeline = run_timeline(Path(out), started, wall, jobs)
    result = {"wall": wall, "output": output, **timeline}
    return {**result, **_memory(sampler, child.pid)} if watched else result


def _memory(sampler: MemorySampler, command_pid: int) -> dict:
    """The peaks of a watched sweep (kB): the command, the fork server, and the largest worker's RSS, PSS
    and USS. The workers are the fork server's children; without a fork server (spawn), the command's
    descendants other than its helpers (a short-lived child such as ``git``, which the code fingerprint
    runs, is then counted too)."""
    command = sampler.hwm.get(command_pid, 0)
    servers = {pid for pid, role in sampler.helpers.items() if role == "fork server"}
    server = max((sampler.hwm.get(pid, 0) for pid in servers), default=0)
    workers = ({pid for pid in sampler.hwm if sampler.parent.get(pid) in servers} if servers
               else set(sampler.hwm) - {command_pid, *sampler.helpers})

    def peak(table):
        return max((table.get(pid, 0) for pid in workers), default=0)

    return {
        "server_kb": server,
        "worker_pss_kb": peak(sampler.pss),
        "worker_uss_kb": peak(sampler.uss),
        "command_kb": command,
        "worker_kb": peak(sampler.hwm),
        "processes": len(workers),
        "total_kb": sampler.peak_total,
        "rusage_children_kb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss,
    }


def _table(output: str) -> list[str]:
    """The order table's lines of a ``neurocur run`` output (without the ``results:`` line, whose folder differs)."""
    return [line for line in output.splitlines() if not line.startswith("results:")]


def run_timeline(out: Path, started: float, wall: float, jobs: int) -> dict:
    """Where a sweep's wall time goes, from each run's own compute time (``seconds`` of its
    ``run.json``, measured in its worker) and the time its ``run.json`` was written: the start-up
    before the first run starts (imports, fork server, pre-flight), the span of the runs, and what
    follows the last (summary, order table, exit). The first run of each worker (the first ``jobs``
    to start) is reported apart (it touches its memory first; before the fork server loaded the
    compiled kernels for every worker, :mod:`neurocur.experiments.warm`, it also loaded them, 0.3 s),
    so the mean of the others is a run's cost in a long sweep."""
    from neurocur.results import ResultsStore
    from neurocur.results.store import RUN_INFO

    store = ResultsStore(out)
    runs = []  # (start, end, seconds), relative to the command's start
    for folder in store.run_dirs():
        end, seconds = (folder / RUN_INFO).stat().st_mtime - started, store.run_info(folder)["seconds"]
        runs.append((end - seconds, end, seconds))
    runs.sort()
    seconds = [s for _, _, s in runs]
    later = seconds[jobs:] or seconds
    last = max(end for _, end, _ in runs)
    return {"startup": runs[0][0], "span": last - runs[0][0], "after": wall - last,
            "first_run": sum(seconds[:jobs]) / len(seconds[:jobs]), "later_run": sum(later) / len(later)}


def incsfa_alone(steps: int, condition: str) -> float:
    """Seconds of ``IncSFA.partial_fit`` on ``steps`` frames of S-A in visits of 100, the learner
    built as the condition's EC builds its adaptive module."""
    import numpy as np

    from neurocur.contexts.synthetic import SyntheticWorld
    from neurocur.experiments import load_experiment

    cond = load_experiment(EXPERIMENT).select([condition])[0]
    world = SyntheticWorld(["S-A"])
    world.reset(seed=0)
    frames = world.context_frames(0)
    visits = [frames[s : s + 100] for s in range(0, len(frames), 100)]
    models = []
    for _ in range(2):  # the first is a warm-up: numba's compilation
        ec = cond.circuit.specs["EC"].make()
        ec.reset(np.random.default_rng(0))
        models.append(ec.adaptive)
    models[0].partial_fit(visits[0])
    start = time.perf_counter()
    for i in range(steps // 100):
        models[1].partial_fit(visits[i % len(visits)])
    return time.perf_counter() - start


def warmed_up(condition: str):
    """``(experiment, condition)`` of the synthetic experiment, after a short run of the condition in
    this process (numba's compilation or cache, the first imports), so that a measurement after it
    counts neither."""
    from neurocur.experiments import load_experiment, run_one

    exp = load_experiment(EXPERIMENT)
    cond = exp.select([condition])[0]
    run_one(cond, 0, 2000, exp.run_seed(0))
    return exp, cond


def core_one(steps: int, condition: str) -> tuple[float, float, float]:
    """(seconds of one run, of them in the IncSFA kernel, in the EC's encoding), in this process."""
    from neurocur.experiments import run_one
    from neurocur.learn import incsfa
    from neurocur.regions import ec

    spent = {"kernel": 0.0, "encoding": 0.0}

    def timed(key, fn):
        def call(*args):
            start = time.perf_counter()
            out = fn(*args)
            spent[key] += time.perf_counter() - start
            return out
        return call

    kernel, step = incsfa.incsfa_fit, ec.ECIncSFA.step
    exp, cond = warmed_up(condition)
    incsfa.incsfa_fit, ec.ECIncSFA.step = timed("kernel", kernel), timed("encoding", step)
    try:
        start = time.perf_counter()
        run_one(cond, 0, steps, exp.run_seed(0))
        total = time.perf_counter() - start
    finally:
        incsfa.incsfa_fit, ec.ECIncSFA.step = kernel, step
    return total, spent["kernel"], spent["encoding"]


def profile_one(steps: int, condition: str) -> tuple[float, list[tuple[str, float]], dict]:
    from neurocur.experiments import run_one

    exp, cond = warmed_up(condition)
    profiler = cProfile.Profile()
    start = time.perf_counter()
    profiler.enable()
    result = run_one(cond, 0, steps, exp.run_seed(0))
    profiler.disable()
    total = time.perf_counter() - start
    table = pstats.Stats(profiler).stats
    rows = []
    for label, suffix, name in COMPONENTS:
        seconds = sum(ct for (file, _, func), (_, _, _, ct, _) in table.items()
                      if func == name and file.replace(os.sep, "/").endswith(suffix))
        rows.append((label, seconds))
    rows.append(("rest: other regions, scheduler, recording", total - sum(s for _, s in rows)))
    return total, rows, result.summary


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=25, help="runs of the sweep (default 25)")
    parser.add_argument("--steps", type=int, default=350_000, help="frames per run (default 3.5e5)")
    parser.add_argument("--condition", default="curious", help="condition of neurocur/experiments_data/synthetic.toml")
    parser.add_argument("--jobs", type=int, default=os.cpu_count(), help="worker processes (default: all cores)")
    parser.add_argument("--no-profile", dest="profile", action="store_false", help="skip the per-component profile")
    args = parser.parse_args(argv)

    print(f"sweep: {args.runs} runs x {args.steps} frames of {args.condition!r}, {args.jobs} jobs "
          f"({os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f})")
    s = sweep(args.runs, args.steps, args.condition, args.jobs, watched=False)
    per_run = s["wall"] * args.jobs / args.runs
    print(f"  wall time              {s['wall']:8.1f} s   ({per_run:.2f} s per run per core, "
          f"{3600 / per_run:.0f} runs per core-hour)")
    print("  " + "\n  ".join(line for line in s["output"].splitlines() if line.strip()))
    print(f"  where the wall goes    start-up {s['startup']:.1f} s (imports, fork server, pre-flight), the runs "
          f"{s['span']:.1f} s, after the last run {s['after']:.1f} s (summary, order table, exit)")
    print(f"  a run in its worker    {s['later_run']:.2f} s (each worker's first run: {s['first_run']:.2f} s)")
    m = sweep(args.runs, args.steps, args.condition, args.jobs, watched=True)
    if _table(m["output"]) != _table(s["output"]):
        raise SystemExit("the watched sweep's order table differs from the timed one's (same seeds)")
    print(f"the same sweep again, its memory sampled every 0.1 s (wall {m['wall']:.1f} s, slowed by the sampling; "
          f"order table identical):")
    print(f"  peak RSS, command      {m['command_kb'] / 1024:8.1f} MB")
    print(f"  peak RSS, fork server  {m['server_kb'] / 1024:8.1f} MB   (the modules every worker shares)")
    print(f"  peak RSS, largest worker {m['worker_kb'] / 1024:6.1f} MB   ({m['processes']} workers)")
    print(f"  peak PSS, largest worker {m['worker_pss_kb'] / 1024:6.1f} MB   (pages shared with the forkserver "
          f"counted in proportion)")
    print(f"  peak USS, largest worker {m['worker_uss_kb'] / 1024:6.1f} MB   (its private pages only: what each "
          f"further worker adds)")
    print(f"  peak RSS, all at once  {m['total_kb'] / 1024:8.1f} MB")
    print(f"  getrusage children     {m['rusage_children_kb'] / 1024:8.1f} MB   (largest reaped descendant)")
    alone = incsfa_alone(args.steps, args.condition)
    print(f"IncSFA alone on {args.steps} frames: {alone:.2f} s; a run per core is {per_run / alone:.1f}x that, "
          f"a run in its worker (a long sweep's cost per run) {s['later_run'] / alone:.1f}x "
          f"(load average {os.getloadavg()[0]:.2f})")
    total, kernel, encoding = core_one(args.steps, args.condition)
    turns = -(-args.runs // args.jobs)
    print(f"one run in this process: {total:.2f} s; the IncSFA kernel {kernel:.2f} s and the EC's encoding "
          f"{encoding:.2f} s ({kernel + encoding:.2f} s), the rest {total - kernel - encoding:.2f} s. "
          f"{args.runs} runs in {TARGET_WALL:g} s wall with {args.jobs} jobs leave {TARGET_WALL / turns:.2f} s per run, "
          f"start-up included "
          f"({turns} runs per worker)")
    if args.profile:
        total, rows, summary = profile_one(args.steps, args.condition)
        print(f"\nprofile of one run in this process: {summary['frames']} frames, {summary['n_episodes']} episodes, "
              f"{summary['n_modules']} modules, {total:.2f} s under cProfile")
        width = max(len(label) for label, _ in rows)
        print(f"  {'component':<{width}}  {'seconds':>8}  {'share':>6}")
        for label, seconds in rows:
            print(f"  {label:<{width}}  {seconds:8.2f}  {seconds / total:6.1%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
