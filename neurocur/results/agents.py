"""Checkpoints and saved agents: a simulator's state at an episode boundary, written and read back.

A simulator (:class:`~neurocur.scheduler.Simulator`) is rebuilt from its circuit, world and
seed exactly as a fresh run starts; what a run changes lives in its regions (the EC module
library, the HPC clusterers, the PFC values, the LC state, their random generators), its
world (the context sequence, its generators), its recorder (the tables so far) and the
simulator's own counters and signal values. :func:`save_simulator` writes all of these
with the generic state walker (:mod:`.statefile`: JSON and ``.npz``, no pickle), and
:func:`restore_simulator` puts them back into a freshly built simulator of the same
condition and seed, which then continues the run: the tables are bit-identical to those of
a run that was never stopped.

* **Checkpoints** (:class:`Checkpoints`): a long run saves its simulator every ``every``
  episodes into ``OUT/checkpoints/<condition>/run-<NNN>/``; a run started again (after a kill,
  a lost machine) continues from there instead of from its first frame, and the folder goes
  when the run is written. :func:`checkpoint_every` says how often by default.
* **Saved agents** (:func:`agent_state`): the state of a finished run, written with the run
  as ``OUT/runs/<condition>/run-<NNN>/agent/``, which
  :func:`neurocur.experiments.agent.load_agent` builds back into a simulator that can be
  probed or continued.
"""

from __future__ import annotations

import contextlib
import shutil
from collections.abc import Mapping
from pathlib import Path

from .statefile import StateError, encode_state, load_state, read_meta, save_state

__all__ = ["AGENT", "CHECKPOINT_EPISODES", "CHECKPOINT_FROM_STEPS", "Checkpoints", "agent_state", "checkpoint_every",
           "restore_simulator", "save_simulator"]

#: the folder of a run folder that holds its saved agent
AGENT = "agent"
#: runs of at least this many frames save a checkpoint by default (a paper-size synthetic run, 3.5e5
#: frames, takes minutes; the iCub run and a 1e6-frame run take much longer)
CHECKPOINT_FROM_STEPS = 200_000
#: the default interval: a checkpoint every this many episodes (about 30 000 frames of the
#: synthetic world, whose episodes last about 160 frames; a save takes a fraction of a second)
CHECKPOINT_EPISODES = 200


class _Counters:
    """The simulator's own state between two episodes (its frame and episode counters and the
    signal values that delayed edges carry into the next episode)."""

    def __init__(self, sim):
        self.n_frames, self.n_episodes, self.values = sim.n_frames, sim.n_episodes, sim._values


def _roots(sim) -> dict:
    return {"simulator": _Counters(sim), "world": sim.world, "recorder": sim.recorder,
            **{f"region.{name}": region for name, region in sim.regions.items()}}


def save_simulator(sim, folder, meta: Mapping | None = None) -> Path:
    """Write ``sim``'s state (between two episodes) into ``folder``; ``meta`` (plain JSON) is kept beside it."""
    return save_state(folder, _roots(sim), {**(meta or {}), "n_frames": sim.n_frames, "n_episodes": sim.n_episodes})


def restore_simulator(sim, folder) -> dict:
    """Put the state saved in ``folder`` into ``sim``, freshly built for the same circuit, world and seed;
    returns the saved ``meta``."""
    roots = _roots(sim)
    meta = load_state(folder, roots)
    counters = roots["simulator"]
    sim.n_frames, sim.n_episodes, sim._values = counters.n_frames, counters.n_episodes, counters.values
    return meta


def agent_state(sim, meta: Mapping | None = None) -> tuple[dict, dict]:
    """A finished run's simulator as ``(body, arrays)`` (:func:`~.statefile.encode_state`), which
    the results store writes as the run's ``agent/`` folder."""
    return encode_state(_roots(sim), {**(meta or {}), "n_frames": sim.n_frames, "n_episodes": sim.n_episodes})


def checkpoint_every(steps: int, every: int | None = None) -> int:
    """Episodes between two checkpoints of a run of ``steps`` frames: ``every`` when given (0: none),
    else :data:`CHECKPOINT_EPISODES` for runs of at least :data:`CHECKPOINT_FROM_STEPS` frames and 0 below."""
    if every is not None:
        return max(0, int(every))
    return CHECKPOINT_EPISODES if steps >= CHECKPOINT_FROM_STEPS else 0


def remove_empty(top: Path) -> None:
    """Remove the folders in ``top`` that are empty, then ``top`` when it is; links and files are left alone."""
    if top.is_symlink() or not top.is_dir():
        return
    for folder in [*(d for d in top.iterdir() if d.is_dir() and not d.is_symlink()), top]:
        with contextlib.suppress(OSError):  # not empty: a run's checkpoint kept for resuming
            folder.rmdir()


class Checkpoints:
    """The checkpoints of one run in ``folder``: call it after every episode (it saves every
    ``every`` episodes); :meth:`resume` continues a freshly built simulator from the last one.

    ``meta`` (the run's condition, number, seed and steps) is saved with each checkpoint and must
    match on resume: a checkpoint of another run is never continued. ``required``: the
    checkpoints (or the agent) were asked for, so a simulator whose state the walker cannot
    save (e.g. a world holding a Python function) is an error when the run starts; otherwise
    (checkpoints on by default) the run goes on without them."""

    def __init__(self, folder, every: int, meta: Mapping, *, required: bool = False):
        self.folder = Path(folder)
        self.every = int(every)
        self.meta = dict(meta)
        self.required = required

    def __call__(self, sim) -> None:
        if self.every and sim.n_episodes % self.every == 0:
            save_simulator(sim, self.folder, self.meta)

    def resume(self, sim) -> bool:
        """Put the last checkpoint into ``sim`` (freshly built) when there is one of this run; a
        checkpoint that cannot be read, or of another run, is removed and the run starts afresh.
        First checks that ``sim``'s state can be saved at all (see ``required``)."""
        try:
            encode_state(_roots(sim))
        except StateError as exc:
            if self.required:
                raise StateError(f"condition {self.meta.get('condition')!r}: checkpoints and saved agents need "
                                 f"state the walker takes; {exc}") from None
            self.every = 0
            return False
        try:
            meta = read_meta(self.folder)
        except StateError:
            self.clear()
            return False
        if {k: meta.get(k) for k in self.meta} != self.meta:
            self.clear()
            return False
        restore_simulator(sim, self.folder)
        return True

    def clear(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)
