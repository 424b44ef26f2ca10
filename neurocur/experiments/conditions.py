"""What the experiment entrance makes: an :class:`Experiment` of :class:`Condition` objects, each
with its circuit built and its world's parameters checked (:func:`neurocur.experiments.load_experiment`).

**Seeds (paired design).** Run *i* of every condition uses the same seed,
``SeedSequence(seed, spawn_key=(i,))`` (the *i*-th child of ``SeedSequence(seed).spawn``):
the world (mixing matrices, S-D, clock offsets; seeded under its own key,
:func:`neurocur.scheduler.world_seed`) and every random draw of the circuit (each region's
under its name, :func:`neurocur.scheduler.region_seed`) start from the same state, so
conditions are compared run by run. The seeds do not
depend on the number of runs, the conditions chosen or the number of worker processes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

import neurocur
from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.contexts import DEFAULT_WORLD, WORLDS, World
from neurocur.results.runinfo import seeds_record

__all__ = ["Condition", "Experiment"]


@dataclass(frozen=True)
class Condition:
    """One condition: its circuit (loaded once, overrides applied), the circuit file, the
    ``"REGION.param"`` overrides and the world table.

    Parameters
    ----------
    name : str
        The condition's name (its folder's, a sweep point's label included).
    circuit_path : path
        The circuit file.
    params : dict
        The ``"REGION.param"`` overrides.
    world : dict
        The world table.
    circuit : Circuit
        The circuit, overrides applied.
    world_params : object
        The world's checked parameters.
    description : str
        What the condition is.
    sweep : dict
        The sweep point of this condition (``{"LC.gain": 0.5}``); empty without a sweep.
    fit : tuple of str
        The ``"REGION.param"`` keys ``neurocur fit`` fits when none is given (the file's ``fit``).
    """

    name: str
    circuit_path: Path
    params: dict
    world: dict
    circuit: Circuit
    world_params: object = None
    description: str = ""
    #: the sweep point of this condition (``{"LC.gain": 0.5}``); empty without a sweep
    sweep: dict = field(default_factory=dict)
    #: the ``"REGION.param"`` keys ``neurocur fit`` fits when none is given (the file's ``fit``)
    fit: tuple[str, ...] = ()

    @property
    def world_type(self) -> str:
        return self.world.get("type", DEFAULT_WORLD)

    @property
    def world_class(self) -> type[World]:
        return WORLDS.get(self.world_type)

    def make_world(self) -> World:
        return self.world_class.from_params(self.world_params)


@dataclass(frozen=True)
class Experiment:
    """A loaded, validated experiment.

    Parameters
    ----------
    name : str
        The experiment's name.
    path : path or None
        Its file.
    description : str
        What it asks.
    runs : int
        The runs of each condition.
    steps : int
        The frames of each run.
    seed : int or None
        The experiment's seed; None when neither the file nor --set gave one.
    conditions : dict of str to Condition
        The conditions, by name.
    control : str, optional
        The condition the others are a test against (the file's ``control``), if any.
    """

    name: str
    path: Path | None
    description: str
    runs: int
    steps: int
    seed: int | None
    conditions: dict[str, Condition]
    #: the condition the others are a test against (the file's ``control``), if any
    control: str | None = None

    def run_seed(self, run: int) -> np.random.SeedSequence:
        """The seed of run ``run`` (the same for every condition: paired comparison)."""
        if self.seed is None:
            raise ValueError("this experiment has no seed yet (give one in the file or with --set seed=N)")
        return np.random.SeedSequence(self.seed, spawn_key=(int(run),))

    def with_seed(self, seed: int) -> Experiment:
        return replace(self, seed=int(seed))

    def select(self, names: Sequence[str] | None = None) -> list[Condition]:
        """The named conditions (all when ``names`` is empty); a condition's name without a sweep
        point selects all its points; unknown names list the known ones."""
        if not names:
            return list(self.conditions.values())
        chosen = {}
        for n in names:
            found = [c for c in self.conditions.values() if n in (c.name, c.name.partition("@")[0])]
            if not found:
                known = dict.fromkeys(n.partition("@")[0] for n in self.conditions)
                raise ConfigError(f"--condition {n}", None, f"one of {', '.join(known)}", "an unknown condition")
            chosen.update((c.name, c) for c in found)
        return list(chosen.values())

    def resolved(self) -> dict:
        """The fully resolved experiment, as written to a results folder's ``config.toml``."""
        conditions = {}
        for cond in self.conditions.values():
            conditions[cond.name] = {
                "description": cond.description,
                "circuit": str(cond.circuit_path),
                "params": dict(cond.params),
                "world": dict(cond.world),
                **({"sweep": dict(cond.sweep)} if cond.sweep else {}),
                **({"fit": list(cond.fit)} if cond.fit else {}),
                "resolved_circuit": cond.circuit.to_dict(),
            }
        return {
            "neurocur_version": neurocur.__version__,
            "experiment": str(self.path) if self.path else "",
            "name": self.name,
            "description": self.description,
            "runs": self.runs,
            "steps": self.steps,
            "seeds": seeds_record(self.seed),
            "conditions": conditions,
            **({"control": self.control} if self.control is not None else {}),
        }
