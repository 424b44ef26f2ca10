"""One run: a condition's circuit on its world, from a seed, to tidy tables.

The runner knows no region by name: it reads the circuit's end-of-run products
(:meth:`neurocur.scheduler.Simulator.products`): ``"modules"``, the stored-module table,
and ``"library"``, the frozen modules, which the world judges against its hidden
sources (:meth:`neurocur.contexts.base.World.module_report`).

:func:`dry_run` runs a condition's first episode, to check it (and measure its memory)
before any worker starts.
"""

from __future__ import annotations

import math
import time
import tracemalloc
from collections.abc import Sequence

import numpy as np
import pandas as pd

from neurocur.config import ConfigError
from neurocur.contract import MODULE_COLUMNS
from neurocur.results import RunResult
from neurocur.results.agents import agent_state
from neurocur.results.runinfo import seed_json

from .conditions import Condition

__all__ = ["dry_run", "run_one"]


def _gates(episodes: pd.DataFrame, modules: pd.DataFrame, names: Sequence[str]) -> list[str]:
    """Per module, the names of the contexts whose later episodes it gated (comma-separated)."""
    out = []
    for row in modules.itertuples(index=False):
        later = episodes[(episodes["episode"] > row.episode) & (episodes["gating_module"] == row.module)]
        out.append(",".join(names[c] for c in sorted(later["context"].unique())))
    return out


def run_one(condition: Condition, run: int, steps: int, seed: np.random.SeedSequence, *, progress=None,
            checkpoints=None, save_agent: bool = False) -> RunResult:
    """Simulate one run of ``condition`` for ``steps`` frames from ``seed``.

    Adds ``condition``, ``run`` and the condition's sweep values (one column per swept key)
    in front of the episodes and modules tables, and per
    module ``source`` (the source of the context it was learned in), ``quality`` and the
    world's further columns (:meth:`~neurocur.contexts.base.World.module_report`, which
    may also add per-run tables, e.g. the iCub's ``features``), and ``gates`` (the names
    of the contexts whose episodes it gated after it was stored, comma-separated).

    ``checkpoints`` (:class:`~neurocur.results.agents.Checkpoints`): continue from the run's last
    checkpoint, if any, and save one every so many episodes. ``save_agent``: keep the trained
    agent's state in the result (written as the run folder's ``agent/``).

    Parameters
    ----------
    condition : Condition
        The run's condition.
    run : int
        The run's index.
    steps : int
        The frames to simulate (whole episodes: the run ends with the episode that reaches it).
    seed : numpy.random.SeedSequence
        The run's seed ([`Experiment.run_seed`][neurocur.experiments.conditions.Experiment.run_seed]).
    progress : callable, optional
        ``progress(frames_done)``, called after every episode ([`Simulator.run`][neurocur.scheduler.Simulator.run]);
        None: nothing.
    checkpoints : Checkpoints, optional
        The run's checkpoints (see above); None: none.
    save_agent : bool
        Keep the trained agent's state in the result (see above).

    Returns
    -------
    RunResult
        The run's tables and summary (``run.json``: seed, steps, frames, modules, contexts, seconds, ...).
    """
    started = time.perf_counter()
    world = condition.make_world()
    sim = condition.circuit.build(world, seed=seed)
    if checkpoints is not None:
        checkpoints.resume(sim)
    sim.run(max(0, steps - sim.n_frames), progress=progress, checkpoint=checkpoints)
    episodes = sim.episodes()
    products = sim.products()
    empty = pd.DataFrame({c.name: np.empty(0, np.int64) for c in MODULE_COLUMNS})
    modules = products.get("modules", empty)
    names = world.context_names
    sources, quality, columns, tables = world.module_report(products.get("library", []), modules)
    modules = modules.assign(source=pd.Series(sources, dtype=object, index=modules.index),
                             quality=pd.Series(quality, dtype=np.float64, index=modules.index),
                             gates=pd.Series(_gates(episodes, modules, names), dtype=object, index=modules.index),
                             **{k: pd.Series(v, dtype=np.float64, index=modules.index) for k, v in columns.items()})
    for table in (episodes, modules, *tables.values()):
        table.insert(0, "condition", condition.name)
        table.insert(1, "run", int(run))
        for i, (key, value) in enumerate(condition.sweep.items()):  # a sweep point's values, as columns
            table.insert(2 + i, key, value)
    summary = {
        "condition": condition.name,
        "run": int(run),
        **({"sweep": dict(condition.sweep)} if condition.sweep else {}),
        "seed": seed_json(seed),
        "steps": int(steps),
        "frames": int(episodes["n_frames"].sum()),
        "n_episodes": len(episodes),
        "n_modules": len(modules),
        "order": sources,
        "module_steps": [int(s) for s in modules["step"]],
        "quality": [None if math.isnan(q) else q for q in quality],
        "contexts": [{"name": n, "source": s} for n, s in zip(names, world.source_names)],
        "learnable": list(world.source_spec().learnable),
        "seconds": round(time.perf_counter() - started, 3),
    }
    agent = agent_state(sim, {"condition": condition.name, "run": int(run), "steps": int(steps),
                              "seed": summary["seed"]}) if save_agent else None
    return RunResult(condition.name, int(run), episodes, modules, summary, tables, agent)


def dry_run(condition: Condition, seed: np.random.SeedSequence) -> int:
    """Run ``condition``'s first episode as a run starts (world, circuit, one episode), to check
    it; returns the peak memory that episode allocates, in bytes.

    The episode runs twice: first to check it and to load the compiled kernels (whose
    loading ``tracemalloc`` would slow down severalfold), then under ``tracemalloc``, which
    sees numpy's arrays. A ValueError names the condition and keeps the region's message; a
    ConfigError of the world's parameters (checked again at build, e.g. a module that does not
    import) is raised as it is, for the caller to name the experiment file.

    Parameters
    ----------
    condition : Condition
        The condition to check.
    seed : numpy.random.SeedSequence
        The seed its first run starts from.

    Returns
    -------
    int
        The peak memory the episode allocated, in bytes.

    Raises
    ------
    ValueError
        When the episode fails, naming the condition.
    ConfigError
        For the world's parameters, as raised.
    """
    try:
        _first_episode(condition, seed)
        tracing = tracemalloc.is_tracing()
        if tracing:
            tracemalloc.reset_peak()
        else:
            tracemalloc.start()
        try:
            base = tracemalloc.get_traced_memory()[0]
            _first_episode(condition, seed)
            return tracemalloc.get_traced_memory()[1] - base
        finally:
            if not tracing:
                tracemalloc.stop()
    except ConfigError as exc:
        if exc.source == type(condition.world_params).__name__:  # the world's parameters: the caller names the file
            raise
        raise ValueError(f"condition {condition.name!r}: {exc}") from None
    except ValueError as exc:
        raise ValueError(f"condition {condition.name!r}: {exc}") from None


def warm_up() -> None:
    """Run the first episode of the shipped synthetic experiment's curious condition, which loads
    the compiled kernels it calls (:mod:`neurocur.experiments.warm`). Any error is left to the
    runs themselves to report: here it only forgoes the saving."""
    from .spec import load_experiment

    try:
        experiment = load_experiment("synthetic")
        _first_episode(experiment.conditions["curious"], experiment.run_seed(0))
    except Exception:  # an optimisation: a real error surfaces in the runs
        pass


def _first_episode(condition: Condition, seed: np.random.SeedSequence) -> None:
    world = condition.make_world()
    for spec in condition.circuit.specs.values():
        spec.make().bind(world)  # the regions' checks against the world, before it renders its frames
    condition.circuit.build(world, seed=seed).run(1)
