"""The decision part's inputs: recorded in a replay's full run, played back to the part as a circuit of its own.

A cached replay (:mod:`neurocur.fit.replay`) runs the whole circuit once, with the regions of the
*decision part* (the decision region and the regions between a fitted parameter and it) as
:func:`taped` classes that record their step inputs pass by pass, the decision region emitting and
scoring the observed decisions. A likelihood evaluation steps the decision part again with other
parameters on those recorded inputs. :func:`part_circuit` makes that a circuit like any other, the
cut of ``neurocur.rl.path`` for the same job: the decision part's regions and their edges among
themselves, and in place of everything else one :class:`Playback` region, which

- emits, on each pass, every input of the part that came from outside it (or from the decision's
  observed outputs: the action and next context the data show) as the run delivered it, delay
  included, into the same input by an edge that is not delayed;
- reads, in its learn phase (it does not learn), every output of the part that the rest of the
  circuit read in the run, so that each region is wired (:attr:`~neurocur.regions.Region.wired`)
  as it was in the run.

:meth:`~neurocur.circuit.Circuit.build` on the run's world with the run's seed sequence gives every
region the generator it had in the run (:func:`~neurocur.scheduler.region_seed` keys it by the
region's name; a drug's stream under it), and :meth:`~neurocur.scheduler.Simulator.run` steps the
part in the scheduler's order, with its delayed slots and its outputs' initial values.
In the part's circuit the decision region is a :func:`scoring` class, which keeps log P of each observed
decision; :class:`InputTape` stands in for it where only the decision's inputs are wanted (the upstream
part's outputs for a vectorised decision): it records them without stepping the decision.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence

import numpy as np

from ..circuit import Circuit, Link, RegionSpec
from ..circuit.specs import ports
from ..config import ConfigError
from ..regions.base import NoParams, Region, Signal

__all__ = ["TAPE", "InputTape", "Playback", "part_circuit", "retyped", "scoring", "taped"]

#: the name of the :class:`Playback` region in a part's circuit (not a name a circuit file declares)
TAPE = "<tape>"


class Playback(Region):
    """Emits recorded values, one row per pass, and reads the outputs the rest of the circuit read.

    Parameters
    ----------
    name : str
        The region's name in the part's circuit (:data:`TAPE`).
    params : optional
        Unused: the region has no parameters.
    outputs : sequence of Signal
        One output per recorded input, named ``"REGION.input"``.
    rows : sequence of tuple
        Per pass, the values of ``outputs`` in order; shared, never copied (a built circuit copies
        the region, :meth:`~neurocur.circuit.specs.RegionSpec.make`).
    reads : sequence of Signal
        Its learn-phase inputs, one per output the rest of the circuit read, named ``"REGION.output"``.
    """

    type_name = "fit.playback"

    def __init__(self, name: str = "", params=None, *, outputs: Sequence[Signal] = (), rows: Sequence[tuple] = (),
                 reads: Sequence[Signal] = ()):
        super().__init__(name, params)
        self.outputs = tuple(outputs)
        self.learn_inputs = tuple(reads)
        self.rows = rows

    def __deepcopy__(self, memo):
        region = copy.copy(self)
        region.events = []
        return region

    def reset(self, rng) -> None:
        self.t = 0

    def step(self):
        row, self.t = self.rows[self.t], self.t + 1
        return row


class InputTape(Region):
    """Records its step inputs, pass by pass, in :attr:`tape`, and emits nothing: the decision
    region's stand-in when only its inputs are wanted.

    Parameters
    ----------
    name : str
        The decision region's name.
    params : optional
        Unused: the region has no parameters (``Region``'s constructor takes them).
    inputs : sequence of Signal
        The decision region's step inputs.
    """

    type_name = "fit.input_tape"

    def __init__(self, name: str = "", params=None, *, inputs: Sequence[Signal] = ()):
        super().__init__(name, params)
        self.inputs = tuple(inputs)

    def reset(self, rng) -> None:
        self.tape = []

    def step(self, *inputs):
        self.tape.append(inputs)
        return ()


def part_circuit(circuit: Circuit, part: Sequence[str], tapes: Mapping[str, Sequence[tuple]], *,
                 decision: RegionSpec, observed: Sequence[str]) -> Circuit:
    """The decision part of ``circuit`` as a circuit fed by a :class:`Playback` of its recorded inputs.

    Parameters
    ----------
    circuit : Circuit
        The whole circuit the run stepped.
    part : sequence of str
        The decision part's regions (:func:`~neurocur.fit.part.decision_part`); none of them may read
        learn-phase inputs (their values are not recorded).
    tapes : mapping of str to sequence of tuple
        Per region of ``part``, its step inputs on each pass of the run, as the scheduler delivered them.
    decision : RegionSpec
        The decision region's spec in the part's circuit (its name names the decision region): a region
        that scores the observed decision, or an :class:`InputTape`.
    observed : sequence of str
        The decision's outputs that the data replace (``"action"``, ``"next_context"``): a region of the
        part that reads one is given the recorded value.

    Returns
    -------
    Circuit
        The regions of ``part`` (``decision`` in the decision region's place) after the :data:`TAPE`
        region, with the edges of ``circuit`` between them that do not carry an observed output, and
        edges from and to :data:`TAPE` for the rest.
    """
    name, members = decision.name, set(part)
    specs = {n: decision if n == name else circuit.specs[n] for n in part}
    links, outputs, columns = [], [], []
    for k in circuit.links:
        if k.dst not in members:
            continue
        if k.src in members and not (k.src == name and k.signal in observed):
            links.append(k)
            continue
        step_inputs = ports(circuit.specs[k.dst], "inputs")
        i = next((j for j, s in enumerate(step_inputs) if s.name == k.input), None)
        if i is None:
            raise ConfigError(circuit.source, f"regions.{k.dst}", "regions of the decision part that read no "
                              "learn-phase input from outside it (only step inputs are recorded)", f"edge {k}")
        port = f"{k.dst}.{k.input}"
        outputs.append(Signal(port, step_inputs[i].dtype, step_inputs[i].shape))
        columns.append((k.dst, i))
        links.append(Link(TAPE, port, k.dst, k.input))
    fed = {(k.src, k.signal) for k in links}
    reads = []
    for k in circuit.links:
        if k.src in members and (k.src, k.signal) not in fed:
            signal = next((s for s in ports(specs[k.src], "outputs") if s.name == k.signal), None)
            if signal is not None:  # an InputTape has none of the decision's outputs
                fed.add((k.src, k.signal))
                reads.append(Signal(f"{k.src}.{k.signal}", signal.dtype, signal.shape))
                links.append(Link(k.src, k.signal, TAPE, reads[-1].name))
    rows = [tuple(tapes[dst][t][i] for dst, i in columns) for t in range(len(tapes[name]))]
    playback = Playback(TAPE, outputs=outputs, rows=rows, reads=reads)
    return Circuit({TAPE: RegionSpec(TAPE, Playback, NoParams(), instance=playback), **specs}, links,
                   source=circuit.source)


def taped(cls: type, observed):
    """A subclass of region class ``cls`` that records its step inputs, pass by pass, in ``tape``.

    Parameters
    ----------
    cls : type
        A region class.
    observed : tuple of three arrays, or None
        For the decision region, per pass, the observed action, the observed next context and the
        decision to score: the region emits the first two in place of its own and keeps
        ``log_probability`` of the third in ``logp``. None for any other region.

    Returns
    -------
    type
        The subclass, with ``cls``'s type name.
    """

    if observed is not None:
        names = [s.name for s in cls.outputs]
        slots = [(names.index(key), j) for j, key in enumerate(("action", "next_context")) if key in names]
        shown = list(zip(np.asarray(observed[0]).tolist(), np.asarray(observed[1]).tolist()))
        scored = observed[2]

    class Taped(cls):
        def reset(self, rng) -> None:
            super().reset(rng)
            self.tape, self.logp, self.t = [], [], 0

        def step(self, *inputs):
            self.tape.append(inputs)
            out = super().step(*inputs)
            if observed is None:
                return out
            t, self.t = self.t, self.t + 1
            self.logp.append(self.log_probability(scored[t]))
            self.shown = shown[t]
            out = list(out)
            for i, j in slots:
                out[i] = self.shown[j]
            return tuple(out)

        def record(self):
            return (*self.shown, *super().record()[2:]) if observed is not None else super().record()

    Taped.__name__ = Taped.__qualname__ = f"Replayed{cls.__name__}"
    Taped.type_name = cls.type_name
    return Taped


def scoring(cls: type, decisions):
    """A subclass of decision region class ``cls`` that keeps, pass by pass, log P of ``decisions[t]`` in
    ``logp`` (its outputs are its own: in a part's circuit none that the data replace is read).

    Parameters
    ----------
    cls : type
        A decision region class (``log_probability``).
    decisions : array
        Per pass, the decision to score.

    Returns
    -------
    type
        The subclass, with ``cls``'s type name.
    """

    class Scoring(cls):
        def reset(self, rng) -> None:
            super().reset(rng)
            self.logp = []

        def step(self, *inputs):
            out = super().step(*inputs)
            self.logp.append(self.log_probability(decisions[len(self.logp)]))
            return out

    Scoring.__name__ = Scoring.__qualname__ = f"Scoring{cls.__name__}"
    Scoring.type_name = cls.type_name
    return Scoring


def retyped(instance, cls: type):
    """A prebuilt region instance as an instance of ``cls`` (a subclass of its class, :func:`taped`, :func:`scoring`).

    Parameters
    ----------
    instance : Region or None
        A region spec's prebuilt instance (left untouched).
    cls : type
        The subclass.

    Returns
    -------
    Region or None
        A copy of ``instance`` of class ``cls``, or None without an instance.
    """
    if instance is None:
        return None
    new = copy.deepcopy(instance)
    new.__class__ = cls
    return new
