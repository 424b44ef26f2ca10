"""The experiment spec: a TOML file → validated conditions, each with its circuit built once.

An experiment file (a path, or the name of one shipped in ``neurocur/experiments_data/``,
e.g. ``"synthetic"``: :func:`resolve_experiment`) names a circuit, the world, the number of
runs and steps, the root seed, parameter overrides and, optionally, conditions::

    name = "synthetic"
    circuit = "cd_misfa"                      # a shipped circuit, or a path relative to this file
    runs = 25
    steps = 350000                            # frames per run
    seed = 2013
    control = "random_switching"              # optional: the conditions' control (see below)

    [world]                                   # neurocur.contexts.synthetic.SyntheticWorld
    contexts = ["S-A", "S-A", "S-B", "S-C", "S-D"]
    normalise = "global"
    # [world.sources]  S-X = "x.npy"          # user driving forces, (n_steps, n_dims)

    [params]                                  # "REGION.param" overrides of the circuit
    "HPC.threshold" = 0.3

    [conditions.curious]                      # a condition: overrides and/or a circuit variant
    [conditions.random_switching]
    circuit = "lesion_lc_random"
    params = { "LC.epsilon0" = 1.0 }          # merged over the top-level [params]
    # world = { normalise = "image" }         # merged over the top-level [world]
    # lesion = [{ region = "LC", how = "clamp", level = 8.0 }]   # lesions and drugs on the circuit
    # replace.LC = { type = "lc.softmax", params = { gain = 3.0 } }      # as a circuit file's [replace.LC]
    # edges = [{ from = "EC", signal = "slowness_progress", to = "VTA", input = "progress" }]  # its [[edges]]

The world table's keys are the parameters of its type (``world.type``, default
``"synthetic"``: :class:`~neurocur.contexts.synthetic.SyntheticParams`; ``"icub"``:
:class:`~neurocur.contexts.icub.ICubParams`; any type registered in
:data:`neurocur.contexts.WORLDS`). Paths in it are relative to the experiment file. A ``circuit`` value is a path when it is
an existing path, ends with ``.toml`` or contains a path separator, and otherwise the name
of a circuit shipped in ``neurocur/circuits/`` (:func:`neurocur.tables.resolve_file`).

A file may extend another, ``extends = "synthetic"``, and state only what differs
(:mod:`neurocur.experiments.resolve`: what is inherited, merged or replaced).

Without a ``[conditions]`` table there is one condition, ``default``. ``control`` names the
condition the others are a test against (e.g. random switching, section 4.3); it goes with the
``[conditions]`` table: a file that extends another inherits its control with its conditions (and
may name another of them), a file with conditions of its own has only the control it names. It is
recorded in ``config.toml``, where the analysis reads it (the efficiency figure of the first
condition against the control, :mod:`neurocur.analysis.figures.sets`). The first condition is the
reference of every comparison. Condition names and sweep labels become folder names
(:mod:`neurocur.results.names`). Command-line
``--set KEY=VALUE`` settings (values are TOML literals; a bare word is a string) win
over the file and over every condition: ``runs``, ``steps``, ``seed``, ``circuit``,
``world.KEY`` or ``REGION.param``. The seeds of the runs: :mod:`neurocur.experiments.conditions`.

:func:`load_experiment` is the entrance's three passes, each entered once:
:func:`~neurocur.experiments.resolve.resolve` reads the file, the files it extends and the
circuit files, with the command line's settings, into one table that remembers where each
value came from; :func:`~neurocur.experiments.expand.expand` takes conditions × sweep points;
:func:`~neurocur.experiments.build.build` builds each one's circuit (kept, so runs never parse
it again) and checks its world's parameters without building the world.

Configuration problems raise :class:`~neurocur.config.ConfigError` naming the file (or
``--set KEY``) and the key.
"""

from __future__ import annotations

from collections.abc import Sequence

from .build import build
from .conditions import Condition, Experiment
from .expand import expand
from .resolve import parse_set, resolve, resolve_experiment, shipped_experiments

__all__ = ["Condition", "Experiment", "load_experiment", "parse_set", "resolve_experiment", "shipped_experiments"]


def load_experiment(path, *, sets: Sequence[str] = (), runs: int | None = None, steps: int | None = None,
                    seed: int | None = None) -> Experiment:
    """Read and validate an experiment file (a path or a shipped experiment's name, e.g. ``"synthetic"``),
    applying ``--set`` items and ``--runs``/``--steps``/``--seed``: resolve, expand, build.

    Parameters
    ----------
    path : str or path
        The experiment file, or a shipped experiment's name.
    sets : sequence of str
        ``--set KEY=VALUE`` items.
    runs : int, optional
        Overrides the file's runs.
    steps : int, optional
        Overrides the file's steps.
    seed : int, optional
        Overrides the file's seed.

    Returns
    -------
    Experiment
        The conditions built, each once.
    """
    resolved = resolve(path, sets=sets, runs=runs, steps=steps, seed=seed)
    return build(resolved, expand(resolved))
