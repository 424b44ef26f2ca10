"""From an experiment and behaviour data to replays and fits: what the ``neurocur fit`` command runs.

The circuit and world are the experiment condition's (:func:`neurocur.experiments.load_experiment`).
Each data set is replayed with its own seed: a results folder's run with the run's seed (so
its world's frames are the run's own), the i-th data set of a table with the experiment's
``run_seed(i)`` (data from agents in the same known world). :func:`simulate` makes a data set
from the condition's circuit at given parameters (recovery, the parametric bootstrap), and
:func:`replay_of` is the one place a data set's replay is built.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from ..config import ConfigError
from ..experiments import load_experiment
from .data import Behaviour, behaviour_from_episodes, read_behaviour
from .mle import MLFit, fit_ml
from .replay import Replay, signal_circuit
from .trials import trials_from_episodes

__all__ = ["check_bound_keys", "condition_of", "default_bounds", "fit_data", "load_data", "make_replays", "model_bounds", "replay_of",
           "simulate"]


def condition_of(experiment, condition: str | None = None):
    """The experiment's condition (a loaded experiment or a name/path), the first when ``condition`` is None.

    Parameters
    ----------
    experiment : Experiment or str
        A loaded experiment, or a shipped experiment's name or a TOML file's path.
    condition : str, optional
        The condition's name.

    Returns
    -------
    (Experiment, Condition)
        The loaded experiment and its condition.
    """
    experiment = load_experiment(experiment) if isinstance(experiment, str) or not hasattr(experiment, "conditions") \
        else experiment
    if condition is None:
        return experiment, next(iter(experiment.conditions.values()))
    if condition not in experiment.conditions:
        raise ConfigError(experiment.path or experiment.name, "--condition",
                          f"one of the conditions {', '.join(experiment.conditions)}", repr(condition))
    return experiment, experiment.conditions[condition]


def load_data(data, condition, *, decision: str = "LC", signal: tuple[str, str] | None = None) -> list[Behaviour]:
    """The data sets of ``data`` (a table or a results folder) in the condition's world.

    Parameters
    ----------
    data : str or path
        A behaviour table or a results folder (:func:`~neurocur.fit.data.read_behaviour`).
    condition : Condition
        The experiment condition (:class:`~neurocur.experiments.conditions.Condition`): its circuit and world.
    decision : str
        The region whose decisions are the data (default the LC).
    signal : (str, str), optional
        (region, column): signal replay, the region replaced by the data set's recorded column.

    Returns
    -------
    list of Behaviour
        One per data set.
    """
    world = condition.make_world()
    spec = condition.circuit.specs.get(decision)
    if spec is None:
        raise ConfigError(condition.circuit.source, "decision", f"a region of the circuit ({', '.join(condition.circuit.specs)})",
                          repr(decision))
    free = getattr(spec.cls, "decides", "action") == "next_context"
    return read_behaviour(data, world.context_names, free_choice=free, signals=[signal[1]] if signal else [])


def simulate(condition, theta: Mapping[str, float], seed, n_episodes: int, *, decision: str = "LC",
             signal: tuple[str, str] | None = None, name: str = "sim"):
    """A data set of ``n_episodes`` simulated by the condition's circuit at ``theta``.

    Parameters
    ----------
    condition : Condition
        The experiment condition (:class:`~neurocur.experiments.conditions.Condition`): its circuit and world.
    theta : mapping of str to float
        ``{"REGION.param": value}`` set on the circuit (empty: its own parameters).
    seed : int or SeedSequence
        The simulation's seed.
    n_episodes : int
        The episodes simulated.
    decision : str
        The region whose decisions are the data (default the LC).
    signal : (str, str), optional
        (region, column): signal replay, the region replaced by the data set's recorded column.
    name : str
        The data set's name.

    Returns
    -------
    (Behaviour or Trials, pandas.DataFrame)
        The data set (the recorded ``signal`` column kept for signal replay; a task of trials gives the
        subject's :class:`~neurocur.fit.trials.Trials`) and the episodes table.
    """
    circuit = condition.circuit.with_params(dict(theta), source="theta") if theta else condition.circuit
    world = condition.make_world()
    sim = circuit.build(world, seed=seed)
    for _ in range(n_episodes):
        sim.run(1)
    episodes = sim.episodes()
    if hasattr(world, "recorded"):  # a task of trials: the subject's Trials (neurocur.fit.trials)
        return trials_from_episodes(episodes, world.context_names, name, f"<simulated {name}>")[0], episodes
    free = getattr(circuit.specs[decision].cls, "decides", "action") == "next_context"
    table = pd.DataFrame({"dataset": name, "episode": episodes["episode"], "context": episodes["context"],
                          "decision": episodes["next_context" if free else "action"]})
    if signal is not None:
        table[signal[1]] = episodes[signal[1]]
    (behaviour,) = behaviour_from_episodes(table, world.context_names, free_choice=free,
                                           signals=[signal[1]] if signal else [], source=f"<simulated {name}>")
    return behaviour, episodes


def replay_of(condition, behaviour: Behaviour, seed, fitted: Sequence[str], *, decision: str = "LC",
              signal: tuple[str, str] | None = None) -> Replay:
    """The data set's cached replay through the condition's circuit with ``seed``.

    Parameters
    ----------
    condition : Condition
        The experiment condition (:class:`~neurocur.experiments.conditions.Condition`): its circuit and world.
    behaviour : Behaviour
        The data set.
    seed : int or SeedSequence
        The replay's seed (the run's own for a results folder's run).
    fitted : sequence of str
        The keys the fit varies.
    decision : str
        The region whose decisions are the data (default the LC).
    signal : (str, str), optional
        (region, column): signal replay, the region replaced by the data set's recorded column.

    Returns
    -------
    Replay
        The data set's replay, its decisions' probabilities cached.
    """
    circuit = condition.circuit if signal is None else signal_circuit(condition.circuit, signal[0], behaviour, signal[1])
    return Replay(circuit, condition.make_world(), seed, behaviour, decision=decision, fitted=fitted)


def make_replays(experiment, condition, datasets: Sequence[Behaviour], fitted: Sequence[str], *,
                 decision: str = "LC", signal: tuple[str, str] | None = None) -> list[Replay]:
    """One cached replay per data set, each with its own seed (module docstring).

    Parameters
    ----------
    experiment : Experiment
        The loaded experiment, whose ``run_seed(i)`` seeds the i-th data set without a seed of its own.
    condition : Condition
        The experiment condition (:class:`~neurocur.experiments.conditions.Condition`): its circuit and world.
    datasets : sequence of Behaviour
        The data sets.
    fitted : sequence of str
        The keys the fit varies.
    decision : str
        The region whose decisions are the data (default the LC).
    signal : (str, str), optional
        (region, column): signal replay, the region replaced by the data set's recorded column.

    Returns
    -------
    list of Replay
        One per data set, in order.
    """
    return [replay_of(condition, behaviour, behaviour.seed if behaviour.seed is not None else experiment.run_seed(i),
                      fitted, decision=decision, signal=signal) for i, behaviour in enumerate(datasets)]


def fit_data(replays: Sequence[Replay], bounds: Mapping[str, tuple[float, float]], *, pooled: bool = True,
             starts: int = 5, seed: int = 0, ci: float | None = 0.95, identify: bool = True) -> list[MLFit]:
    """A fit per data set, then (with ``pooled`` and more than one data set) one pooled fit.

    Parameters
    ----------
    replays : sequence of Replay
        One per data set.
    bounds : mapping of str to (float, float)
        The fitted keys and their bounds.
    pooled : bool
        Also fit all data sets together (when there is more than one).
    starts : int
        The local searches of each fit (:func:`~neurocur.fit.mle.fit_ml`).
    seed : int
        The searches' design seed.
    ci : float or None
        The profile-likelihood intervals' level; None for none.
    identify : bool
        Also find each fit's keys that the data do not identify.

    Returns
    -------
    list of MLFit
        The data sets' fits, then the pooled one.
    """
    fits = [fit_ml(r, bounds, starts=starts, seed=seed, ci=ci, dataset=r.behaviour.name, identify=identify)
            for r in replays]
    for fit, replay in zip(fits, replays):
        if fit.loglik == -np.inf:  # no theta in the bounds gives every observed decision a chance
            where = replay.first_impossible(replay.episode_logp(fit.estimate))
            raise ConfigError(replay.behaviour.source, "decision",
                              "decisions the model gives a nonzero probability somewhere in the bounds",
                              f"log-likelihood -inf: {where}")
    if pooled and len(replays) > 1:
        fits.append(fit_ml(list(replays), bounds, starts=starts, seed=seed, ci=ci, dataset="pooled",
                           identify=identify))
    return fits


def default_bounds(condition, keys: Sequence[str], given: Mapping[str, tuple[float, float]]) -> dict:
    """Bounds for ``keys``: the given ones, else the parameter's declared range where it is finite. Each key is
    a parameter of the circuit, and both ends of given bounds lie in its declared domain (checked as ``--set``
    checks a value, :meth:`~neurocur.config.params.ParamSpec.coerce`).

    Parameters
    ----------
    condition : Condition
        The experiment condition (:class:`~neurocur.experiments.conditions.Condition`): its circuit and world.
    keys : sequence of str
        The fitted keys, ``REGION.param``.
    given : mapping of str to (float, float)
        The ``--bounds`` given.

    Returns
    -------
    dict of str to (float, float)
        Each key's bounds.
    """
    out = {}
    for key in keys:
        region, _, name = key.partition(".")
        spec = condition.circuit.specs.get(region)
        fields = {f.name: f for f in dataclasses.fields(spec.params)} if spec is not None else {}
        if name not in fields:
            raise ConfigError("--fit", key, f"REGION.param, a parameter of the circuit {condition.circuit.source}",
                              "no such region" if spec is None else f"no parameter '{name}' of region '{region}' "
                              f"({', '.join(fields)})")
        ps = fields[name].metadata.get("spec")
        if key in given:
            if ps is not None:
                for end in given[key]:
                    ps.coerce(float(end), source="--bounds", key=key)
            out[key] = given[key]
            continue
        low, high = (getattr(ps, "low", None), getattr(ps, "high", None)) if ps is not None else (None, None)
        if low is None or high is None or not np.isfinite([low, high]).all():
            raise ConfigError("--bounds", key, f"--bounds {key}=LOW:HIGH (the parameter has no finite declared range)",
                              "none")
        out[key] = (float(low), float(high))
    return out


def check_bound_keys(given: Mapping[str, tuple[float, float]], keys: Sequence[str]) -> None:
    """ConfigError for a ``--bounds`` key that is not fitted.

    Parameters
    ----------
    given : mapping of str to (float, float)
        The ``--bounds`` given.
    keys : sequence of str
        The ``--fit`` keys (a ``MODEL:`` prefix is stripped).
    """
    fitted = [key.rpartition(":")[2] for key in keys]
    for key in given:
        if key not in fitted:
            raise ConfigError("--bounds", key, f"bounds of a fitted key ({', '.join(fitted) or 'none fitted'})",
                              "a key no --fit names")


def model_bounds(experiment, names: Sequence[str], keys: Sequence[str],
                 given: Mapping[str, tuple[float, float]]) -> tuple[dict, dict]:
    """The conditions ``names`` of the experiment as models, and each one's bounds (:func:`default_bounds`)
    on the ``keys`` it has. A key ``MODEL:REGION.param`` is fitted in that model only; a plain key in every
    model that has the parameter: not one whose region the condition lacks or lesions (a random LC,
    epsilon fixed at 1, is a model without its decision parameters).

    Parameters
    ----------
    experiment : Experiment or str
        The experiment (as :func:`condition_of` takes it).
    names : sequence of str
        The conditions compared as models.
    keys : sequence of str
        The ``--fit`` keys, ``REGION.param`` or ``MODEL:REGION.param``.
    given : mapping of str to (float, float)
        The ``--bounds`` given.

    Returns
    -------
    (dict, dict)
        Each model's condition, and each model's bounds, by model name.
    """
    models = {name: condition_of(experiment, name)[1] for name in names}
    check_bound_keys(given, keys)
    for key in keys:
        model = key.rpartition(":")[0]
        if model and model not in models:
            raise ConfigError("--fit", key, f"REGION.param or MODEL:REGION.param with MODEL one of {', '.join(names)}",
                              repr(model))
    bounds = {}
    for name, condition in models.items():
        lesioned = {region for region, _, _ in condition.circuit.lesions}
        own = []
        for key in keys:
            model, _, key = key.rpartition(":")
            region, _, param = key.partition(".")
            spec = condition.circuit.specs.get(region)
            if model in ("", name) and spec is not None and hasattr(spec.params, param) and region not in lesioned:
                own.append(key)
        bounds[name] = default_bounds(condition, own, given)
    return models, bounds
