"""A saved agent built back into a simulator: ``neurocur.load_agent(DIR, condition, run)``.

A run computed with ``--save-agent`` (``run_experiment(..., save_agent=True)``) keeps its
trained agent in ``DIR/runs/<condition>/run-<NNN>/agent/`` (:mod:`neurocur.results.agents`).
:func:`load_agent` builds the condition's simulator afresh, from the experiment that the
folder's ``config.toml`` names (or the one given) with the run's seed, and puts the saved
state into it: the result can be probed (``sim.regions["EC"]``'s module library, HPC's
clusterers, PFC's values, LC's state) or continued (``sim.run(frames)``), and a continued
run gives the tables of a run that was computed that long from the start.

Nothing of a saved agent is trusted until it proves itself: its run folder passes the store's
checks (``run.json`` records the sha256 of the agent's files), its own digests match, no link
is followed, its counters are non-negative integers, and the condition, run, seed, steps,
parameters (as ``config.toml`` records them) and code it was saved with are this run's
(:func:`~neurocur.results.agents.restore_simulator`); otherwise a ResultsError of one line
names the file and what did not match.
"""

from __future__ import annotations

import tomllib

from neurocur.results import ResultsError, ResultsStore, dumps_toml, first_difference
from neurocur.results.agents import AGENT, params_digest, restore_simulator
from neurocur.results.fingerprint import local_path, portable
from neurocur.results.runinfo import seed_json
from neurocur.results.safeio import UnsafePath, real_dir
from neurocur.results.statefile import StateError

from .spec import Experiment, load_experiment

__all__ = ["load_agent"]


def load_agent(results_dir, condition: str, run: int, *, experiment: Experiment | None = None):
    """The simulator of run ``run`` of ``condition`` in ``results_dir``, in the state its agent was saved in.

    ``experiment``: the experiment the folder was computed from; default: the experiment file
    named in its ``config.toml``, with its runs, steps and seed. Its condition must be the one the
    folder recorded (resolved circuit and world), else a ResultsError names the first difference
    (an experiment run with ``--set``: load it with the same settings and pass it).

    Parameters
    ----------
    results_dir : path
        The results folder.
    condition : str
        The run's condition.
    run : int
        The run's index.
    experiment : Experiment, optional
        The experiment the folder was computed from (see above); None: the one its ``config.toml`` names.

    Returns
    -------
    neurocur.scheduler.Simulator
        The condition's simulator, built with the run's seed, in the saved state.

    Raises
    ------
    ResultsError
        When the folder holds no such run or no saved agent, ``experiment`` differs from the recorded
        condition, or the agent fails a check (one line naming the file and the key).
    """
    store = ResultsStore(results_dir)
    folder = store.run_dir(condition, int(run))
    if folder not in store.run_dirs():
        raise ResultsError(f"{results_dir} holds no run {run} of condition {condition!r}")
    try:
        saved = real_dir(folder / AGENT)
    except UnsafePath as exc:
        raise ResultsError(str(exc)) from None
    if not saved:
        raise ResultsError(f"{folder} holds no saved agent (run it with --save-agent)")
    if store.run_info(folder).get("agent") is None:
        raise ResultsError(f"{folder / 'run.json'}: key 'agent': expected the sha256 of the saved agent's files, got "
                           "nothing (an agent saved before run.json recorded it, or added since); run it again")
    config = store.config()
    if experiment is None:
        experiment = load_experiment(local_path(config["experiment"]), runs=config["runs"], steps=config["steps"],
                                     seed=config["seeds"]["entropy"])
    if condition not in experiment.conditions:
        raise ResultsError(f"the experiment {experiment.name!r} has no condition {condition!r}")
    chosen = experiment.conditions[condition]
    recorded = config["conditions"][condition]
    built = portable(tomllib.loads(dumps_toml({"world": dict(chosen.world),
                                               "resolved_circuit": chosen.circuit.to_dict()})))
    where = first_difference({k: recorded.get(k) for k in built}, built)
    if where is not None:
        raise ResultsError(f"{store.root / 'config.toml'}: key 'conditions.{condition}.{where}': the experiment "
                           f"{experiment.name!r} gives another value than the run's; pass the experiment it was run "
                           "from (with its --set settings) as experiment=")
    seed = experiment.run_seed(int(run))
    expected = {"condition": condition, "run": int(run), "steps": config["steps"], "seed": seed_json(seed),
                "params": params_digest(config, condition), "code": config.get("code", [])}
    sim = chosen.circuit.build(chosen.make_world(), seed=seed)
    try:
        restore_simulator(sim, folder / AGENT, expected)
    except StateError as exc:
        raise ResultsError(str(exc)) from None
    return sim
