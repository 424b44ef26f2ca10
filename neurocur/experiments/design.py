"""A space-filling design of readings: draws from a declared prior, each a condition of one experiment.

A sweep (:mod:`.expand`) runs the product of its values; a study of many open choices at once
needs points spread over the whole prior instead. :func:`read_prior` reads a prior, one entry
per key::

    [prior]
    "EC.mca_rate" = { log = [0.0125, 0.1] }          # log-uniform
    "PFC.discount" = { linear = [0.5, 0.99] }        # uniform
    "HPC.drift_ratios" = { int = [1, 3] }            # uniform over the integers, both ends included
    "PFC.alpha" = { choice = ["sample_average", 0.2, 0.5] }   # uniform over the values
    "world.normalise" = { choice = ["global", "image"] }
    circuit = { choice = ["vta_state_progress", "cd_misfa"] }

:func:`draws` maps a scrambled Sobol sequence (Sobol 1967; Owen's scrambling, scipy's
``qmc.Sobol``) of 2^m points through each key's scale: every key's 1-D projection then has
exactly one draw in each of the 2^m equal slices of its unit interval, so a choice of k values
that divides 2^m gets exactly 2^m / k draws each. :func:`design_experiment` writes the draws as
the conditions ``d000``, ``d001``, ... of one experiment extending a shipped or given one: a
``"REGION.param"`` key goes to the condition's ``params``, ``"world.KEY"`` to its ``world``,
``circuit`` to its circuit. Run *i* of every draw has the same seed, as for any experiment's
conditions, so the draws are compared run by run, and the runner's store makes the design
resumable and Dask-ready like any experiment (``neurocur run FILE``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from neurocur.config import ConfigError

__all__ = ["SCALES", "design_experiment", "draws", "read_prior", "value_at"]

#: the scales a prior entry may have
SCALES = ("linear", "log", "int", "choice")


def _bounds(source, key: str, scale: str, spec) -> tuple[float, float]:
    ok = (isinstance(spec, list) and len(spec) == 2
          and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in spec))
    if not ok or not spec[0] < spec[1] or (scale == "log" and spec[0] <= 0) \
            or (scale == "int" and not all(isinstance(v, int) for v in spec)):
        kind = {"int": "two integers", "log": "two positive numbers"}.get(scale, "two numbers")
        raise ConfigError(source, f"prior.{key}.{scale}", f"[LOW, HIGH], {kind}, LOW < HIGH", spec)
    return spec[0], spec[1]


def read_prior(table: Mapping, *, source="<prior>") -> dict[str, tuple[str, object]]:
    """``{key: (scale, bounds or values)}`` of a prior table (module docstring), checked: one entry
    per key, a scale of :data:`SCALES`, two increasing bounds (positive for ``log``, integers for
    ``int``), at least two values for ``choice``; keys ``"REGION.param"``, ``"world.KEY"`` or
    ``circuit``.

    Parameters
    ----------
    table : mapping
        The ``[prior]`` table.
    source : path or str
        The file it was read from, named by the errors.

    Returns
    -------
    dict
        ``(scale, [low, high])``, or ``("choice", values)``, by key, in the table's order.

    Raises
    ------
    ConfigError
        For an entry that fails a check, naming ``prior.KEY``.
    """
    if not isinstance(table, Mapping) or not table:
        raise ConfigError(source, "prior", "a table of at least one key", table)
    prior = {}
    for key, entry in table.items():
        if key != "circuit" and ("." not in key or (key.startswith("world.") and key.count(".") > 1)):
            raise ConfigError(source, f"prior.{key}", '"REGION.param", "world.KEY" or circuit', key)
        if not isinstance(entry, Mapping) or len(entry) != 1 or next(iter(entry)) not in SCALES:
            raise ConfigError(source, f"prior.{key}", "one of " + ", ".join(f"{{ {s} = ... }}" for s in SCALES), entry)
        scale, spec = next(iter(entry.items()))
        if scale == "choice":
            if not isinstance(spec, list) or len(spec) < 2:
                raise ConfigError(source, f"prior.{key}.choice", "a list of at least two values", spec)
            prior[key] = (scale, list(spec))
        else:
            prior[key] = (scale, _bounds(source, key, scale, spec))
    return prior


def value_at(scale: str, spec, u: float):
    """The value of a prior entry at the quantile ``u`` in [0, 1).

    Parameters
    ----------
    scale : str
        One of :data:`SCALES`.
    spec : list or tuple
        ``(low, high)``, or the values of a ``choice``.
    u : float
        The quantile, in [0, 1): ``linear`` maps it linearly onto [low, high], ``log`` onto [log low,
        log high] (then exponentiated), ``int`` and ``choice`` onto equal slices, one per integer or value.

    Returns
    -------
    object
        A float (``linear``, ``log``), an int (``int``) or one of the values (``choice``).
    """
    if scale == "choice":
        return spec[min(int(u * len(spec)), len(spec) - 1)]
    low, high = spec
    if scale == "int":
        return int(min(low + math.floor(u * (high - low + 1)), high))
    if scale == "log":
        return float(math.exp(math.log(low) + u * (math.log(high) - math.log(low))))
    return float(low + u * (high - low))


def draws(prior: Mapping[str, tuple[str, object]], n: int, seed: int) -> list[dict]:
    """``n`` draws (a power of two) from ``prior`` (:func:`read_prior`): a scrambled Sobol sequence
    seeded by ``seed``, each coordinate through its key's scale (:func:`value_at`).

    Parameters
    ----------
    prior : mapping
        A checked prior ([`read_prior`][neurocur.experiments.design.read_prior]).
    n : int
        The number of draws: a power of two, at least 2.
    seed : int
        The seed of the Sobol sequence's scrambling.

    Returns
    -------
    list of dict
        The draws, each a value by key.

    Raises
    ------
    ConfigError
        When ``n`` is not a power of two of at least 2.
    """
    from scipy.stats import qmc

    if n < 2 or n & (n - 1):
        raise ConfigError("design", "draws", "a power of two, at least 2 (Sobol's balance)", n)
    u = qmc.Sobol(len(prior), scramble=True, seed=np.random.default_rng(seed)).random_base2(int(math.log2(n)))
    return [{key: value_at(*prior[key], float(x)) for key, x in zip(prior, row)} for row in u]


def design_experiment(base: str, prior: Mapping[str, tuple[str, object]], *, n: int, runs: int, steps: int,
                      seed: int, design_seed: int, name: str = "design", description: str = "") -> dict:
    """One experiment (a TOML table for :func:`neurocur.results.tomlio.dumps_toml`) extending ``base``
    whose conditions ``d000`` ... are the :func:`draws` of ``prior`` (``design_seed``), ``runs`` paired
    runs each of ``steps`` frames from the experiment seed ``seed``.

    Parameters
    ----------
    base : str
        The experiment the design extends (a shipped experiment's name or a path), its ``extends``.
    prior : mapping
        A checked prior ([`read_prior`][neurocur.experiments.design.read_prior]).
    n : int
        The number of draws (conditions): a power of two, at least 2.
    runs : int
        The runs of each condition.
    steps : int
        The frames of each run.
    seed : int
        The experiment's seed (the runs').
    design_seed : int
        The seed of the draws.
    name : str
        The experiment's name.
    description : str
        What it asks.

    Returns
    -------
    dict
        The experiment table; each condition's ``description`` lists its draw.
    """
    conditions = {}
    for i, point in enumerate(draws(prior, n, design_seed)):
        condition: dict = {"description": ", ".join(f"{k} = {v}" for k, v in point.items())}
        params = {k: v for k, v in point.items() if k != "circuit" and not k.startswith("world.")}
        world = {k.removeprefix("world."): v for k, v in point.items() if k.startswith("world.")}
        if "circuit" in point:
            condition["circuit"] = point["circuit"]
        if params:
            condition["params"] = params
        if world:
            condition["world"] = world
        conditions[f"d{i:03d}"] = condition
    return {"extends": base, "name": name, "description": description, "runs": int(runs), "steps": int(steps),
            "seed": int(seed), "conditions": conditions}
