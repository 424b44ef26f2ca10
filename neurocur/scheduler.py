"""The simulator: runs a built circuit pass by pass (one pass = one episode).

Everything that depends on names is resolved once, in the constructor: each region's
outputs get a contiguous range of slots in one value list, each input an index into
it (a delayed edge reads a separate slot that holds the previous pass's value), and
the step phase, the learn phase and the recording are lists of bound methods with
their index tuples. A pass is then::

    for step, in_slots, a, b in step_plan:  values[a:b] = step(*values[in_slots])
    for learn, in_slots in learn_plan:     learn(*values[in_slots])
    for src, dst in delayed:               values[dst] = values[src]
    record probes (one numpy row), frames (if asked), events
"""

from __future__ import annotations

import zlib

import numpy as np
import pandas as pd

from .recording import Recorder

__all__ = ["WORLD_KEY", "Simulator", "region_seed", "world_seed"]

#: the key of a run's world under the run's seed (:func:`world_seed`); no region's key may equal it
WORLD_KEY = "world"


def region_seed(seed: np.random.SeedSequence, name: str) -> np.random.SeedSequence:
    """The seed of region ``name``: a child of ``seed`` keyed by the region's name.

    ``SeedSequence(seed.entropy, spawn_key=seed.spawn_key + (crc32(name),))``: it depends
    on the name only, not on the region's position in the circuit file, so adding,
    removing or reordering regions leaves every other region's random stream unchanged.

    Parameters
    ----------
    seed : numpy.random.SeedSequence
        The run's seed.
    name : str
        The region's name.

    Returns
    -------
    numpy.random.SeedSequence
        The region's seed.
    """
    return np.random.SeedSequence(seed.entropy, spawn_key=(*seed.spawn_key, zlib.crc32(name.encode("utf-8"))),
                                  pool_size=seed.pool_size)


def world_seed(seed: np.random.SeedSequence) -> np.random.SeedSequence:
    """The seed of a run's world: a child of ``seed`` under a key of its own, :data:`WORLD_KEY`,
    beside the regions' (:func:`region_seed`), so that renaming, adding or removing a region
    leaves the world (mixing matrices, S-D, clock offsets, episode orders) unchanged.

    Parameters
    ----------
    seed : numpy.random.SeedSequence
        The run's seed.

    Returns
    -------
    numpy.random.SeedSequence
        The world's seed.
    """
    return region_seed(seed, WORLD_KEY)


class Simulator:
    """A circuit instantiated on a world with a seed; see :meth:`neurocur.circuit.Circuit.build`.

    ``regions``: name -> region instance. Each region's random generator comes from
    :func:`region_seed` (a child of ``seed`` keyed by the region's name); a region under a
    drug (:mod:`neurocur.regions.pharmacology`) gets a second one for the drug, keyed
    ``"drugs"`` under the region's. The world's generator (``world.np_random``, gymnasium's)
    is seeded here from :func:`world_seed`, before any region resets: the clock region then
    starts the world's run from it (:class:`~neurocur.regions.sensory.SensoryWorld`).

    Parameters
    ----------
    circuit : Circuit
        The circuit to instantiate.
    world : World
        The world its clock region binds to.
    seed : numpy.random.SeedSequence
        The run's seed: each region's and the world's generator is a child of it.
    record_frames : bool
        Also record the frame probes (one row per frame).
    """

    def __init__(self, circuit, world, seed, *, record_frames: bool = False):
        self.circuit = circuit
        self.world = world
        self.seed_sequence = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
        names = list(circuit.specs)
        self.regions = {name: circuit.specs[name].make() for name in names}
        children = {name: region_seed(self.seed_sequence, name) for name in names}
        world_key = world_seed(self.seed_sequence)
        if len({child.spawn_key for child in (*children.values(), world_key)}) <= len(names):
            raise ValueError(f"two of the region names {names} and the world's key {WORLD_KEY!r} have the same seed "
                             "key (crc32); rename the region")
        if world is not None:  # a circuit without a world region is built on none
            world.np_random = np.random.default_rng(world_key)
        for name in names:
            region = self.regions[name]
            region.wired = frozenset(k.signal for k in circuit.links if k.src == name)
            region.bind(world)
            region.reset(np.random.default_rng(children[name]))
            if region.drugs:  # the drugs' own stream: the region's draws stay those of the untreated run
                region.drug_rng = np.random.default_rng(region_seed(children[name], "drugs"))

        slot: dict[tuple[str, str], int] = {}
        values: list = []
        self._step_plan = []
        for name in circuit.step_order:
            region = self.regions[name]
            a = len(values)
            for sig in region.outputs:
                slot[(name, sig.name)] = len(values)
                values.append(None)
            self._step_plan.append([region.step, None, a, len(values), name])
        delayed_slot: dict[tuple[str, str], int] = {}
        self._delayed = []
        for link in circuit.links:
            if link.delayed and (link.src, link.signal) not in delayed_slot:
                sig = next(s for s in self.regions[link.src].outputs if s.name == link.signal)
                delayed_slot[(link.src, link.signal)] = len(values)
                self._delayed.append((slot[(link.src, link.signal)], len(values)))
                values.append(sig.initial)
        feeding = {(k.dst, k.input): k for k in circuit.links}

        def slots_of(name, signals):
            out = []
            for sig in signals:
                k = feeding[(name, sig.name)]
                out.append(delayed_slot[(k.src, k.signal)] if k.delayed else slot[(k.src, k.signal)])
            return tuple(out)

        for entry in self._step_plan:
            entry[1] = slots_of(entry[4], self.regions[entry[4]].inputs)
        self._step_plan = [tuple(e) for e in self._step_plan]
        self._learn_plan = [(self.regions[n].learn, slots_of(n, self.regions[n].learn_inputs)) for n in circuit.learn_order]
        self._values = values

        recorded = [(n, self.regions[n].probes, self.regions[n].frame_probes) for n in circuit.step_order]
        self.recorder = Recorder(recorded, record_frames=record_frames)
        self._record_fns = [self.regions[n].record for n in circuit.step_order if self.regions[n].probes]
        self._frame_fns = [(i, self.regions[n].record_frames) for i, n in enumerate(circuit.step_order)
                           if record_frames and self.regions[n].frame_probes]
        self._event_regions = [(n, self.regions[n]) for n in circuit.step_order]
        clocks = [r for r in self.regions.values() if r.is_clock]
        if len(clocks) > 1:
            raise ValueError(f"a circuit has at most one clock region (the episode source); got {len(clocks)}")
        self._clock = clocks[0] if clocks else None
        self.n_frames = 0
        self.n_episodes = 0

    def run(self, n_steps: int, progress=None, checkpoint=None) -> Simulator:
        """Run whole episodes until ``n_steps`` more frames have been seen (at least one episode
        when ``n_steps`` > 0); returns ``self``.

        ``progress``: ``None`` or ``False`` (the default: nothing), or a callable
        ``progress(frames_done)`` called after every episode with the frames seen so far (e.g. a
        ``tqdm`` bar's ``lambda n: bar.update(n - bar.n)``). ``checkpoint(simulator)`` is called
        after every episode too, at the boundary between two episodes: the moment a simulator's
        state can be saved and continued from (:mod:`neurocur.results.agents`)."""
        if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or n_steps < 0:
            raise ValueError(f"n_steps must be a non-negative integer (frames); got {n_steps!r}")
        if progress is False:
            progress = None
        if progress is not None and not callable(progress):
            raise ValueError(f"progress must be None, False or a callable progress(frames_done); got {progress!r}")
        target = self.n_frames + int(n_steps)
        v = self._values
        step_plan, learn_plan, delayed = self._step_plan, self._learn_plan, self._delayed
        record_fns, frame_fns, events = self._record_fns, self._frame_fns, self._event_regions
        rec, clock = self.recorder, self._clock
        while self.n_frames < target:
            start = self.n_frames
            for step, idx, a, b, name in step_plan:
                out = step(*[v[i] for i in idx])
                if len(out) != b - a:
                    raise ValueError(f"region {name!r} step() returned {len(out)} values for {b - a} declared outputs")
                v[a:b] = out
            for learn, idx in learn_plan:
                learn(*[v[i] for i in idx])
            for src, dst in delayed:
                v[dst] = v[src]
            for i, fn in frame_fns:
                rec.append_frames(start, i, fn())
            for name, region in events:
                if region.events:
                    for ev in region.events:
                        rec.append_event(start, name, ev)
                    region.events.clear()
            row = ()
            for fn in record_fns:
                row += fn()
            rec.append(start, row)
            self.n_frames = start + (clock.n_frames if clock is not None else 1)
            self.n_episodes += 1
            if progress is not None:
                progress(self.n_frames)
            if checkpoint is not None:
                checkpoint(self)
        return self

    # ------------------------------------------------------------------ tables

    def episodes(self) -> pd.DataFrame:
        """Wide table, one row per episode (columns documented in docs/regions.md)."""
        return self.recorder.episodes()

    def probes(self) -> pd.DataFrame:
        """Tidy long table ``episode, step, region, signal, value``."""
        return self.recorder.probes()

    def events(self, kind: str | None = None) -> pd.DataFrame:
        """Every event emitted by a region (optionally of one ``kind``)."""
        return self.recorder.events(kind)

    def products(self) -> dict:
        """Every region's end-of-run products by name (:meth:`Region.products`), e.g.
        ``"library"`` (EC's frozen modules) and ``"modules"`` (HPC's stored-module table).
        Two regions producing the same name is an error."""
        events = self.recorder.events()
        found, owner = {}, {}
        for name in self.circuit.step_order:
            for key, value in self.regions[name].products(events[events["region"] == name]).items():
                if key in found:
                    raise ValueError(f"regions {owner[key]!r} and {name!r} both produce the end-of-run product {key!r}")
                found[key], owner[key] = value, name
        return found
