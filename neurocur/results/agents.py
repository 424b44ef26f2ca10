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

Both carry the digests of their files (:mod:`.stateio`) and the run's condition, number, seed,
steps and :func:`provenance` (parameters and code); :func:`restore_simulator` sets nothing
until the state has passed every check. A checkpoint that fails one is discarded with one
line and its run starts afresh; a saved agent that fails one is refused.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .fingerprint import code_fingerprint, portable, same_code
from .safeio import UnsafePath, real_dir, remove_own
from .statefile import StateError, encode_state, load_state, save_state
from .stateio import STATE, debris, write_state

__all__ = ["AGENT", "CHECKPOINT_EPISODES", "CHECKPOINT_FROM_STEPS", "Checkpoints", "agent_state", "checkpoint_every",
           "discard", "params_digest", "provenance", "restore_simulator", "save_simulator", "write_agent"]

#: the folder of a run folder that holds its saved agent
AGENT = "agent"
#: runs of at least this many frames save a checkpoint by default (a paper-size synthetic run, 3.5e5
#: frames, takes minutes; the iCub run and a 1e6-frame run take much longer)
CHECKPOINT_FROM_STEPS = 200_000
#: the default interval: a checkpoint every this many episodes (about 30 000 frames of the
#: synthetic world, whose episodes last about 160 frames; a save takes a fraction of a second)
CHECKPOINT_EPISODES = 200
#: what of a condition's record in ``config.toml`` determines its runs (with the seed and steps)
PARAMS = ("world", "resolved_circuit", "inputs")


class _Counters:
    """The simulator's own state between two episodes (its frame and episode counters and the
    signal values that delayed edges carry into the next episode)."""

    def __init__(self, sim):
        self.n_frames, self.n_episodes, self.values = sim.n_frames, sim.n_episodes, sim._values


def _roots(sim) -> dict:
    return {"simulator": _Counters(sim), "world": sim.world, "recorder": sim.recorder,
            **{f"region.{name}": region for name, region in sim.regions.items()}}


def save_simulator(sim, folder, meta: Mapping | None = None) -> Path:
    """Write ``sim``'s state (between two episodes) into ``folder``; ``meta`` (plain JSON) is kept beside it.

    Parameters
    ----------
    sim : neurocur.scheduler.Simulator
        The simulator, between two episodes.
    folder : path
        The state folder to write (replaced atomically, :func:`~.stateio.write_state`).
    meta : mapping, optional
        Plain JSON kept beside the state (the run's identity and :func:`provenance`); the
        simulator's ``n_frames`` and ``n_episodes`` are added to it.

    Returns
    -------
    path
        The folder written.
    """
    return save_state(folder, _roots(sim), {**(meta or {}), "n_frames": sim.n_frames, "n_episodes": sim.n_episodes})


def restore_simulator(sim, folder, expected: Mapping | None = None) -> dict:
    """Put the state saved in ``folder`` into ``sim``, freshly built for the same circuit, world and seed;
    returns the saved ``meta``.

    Nothing is set unless the state passes every check: the state folder's own
    (:func:`~.stateio.read_state`: digests, declared arrays, no link), the simulator's counters
    (non-negative integers, as its ``meta`` and its recorder say) and each key of ``expected``
    against the saved ``meta`` (``code``: a list of the code fingerprints it may have been
    saved by). A StateError of one line names the file and what did not match.

    Parameters
    ----------
    sim : neurocur.scheduler.Simulator
        A simulator freshly built for the run's circuit, world and seed; set only when every check passes.
    folder : path
        The state folder (a checkpoint or a saved agent).
    expected : mapping, optional
        Keys the saved ``meta`` must hold with these values (``code``: a fingerprint or a list of
        them, compared with :func:`~.fingerprint.same_code`); None checks none.

    Returns
    -------
    dict
        The saved ``meta``.

    Raises
    ------
    StateError
        When the state fails a check, naming the file and the key.
    """
    roots = _roots(sim)
    where = Path(folder) / STATE

    def check(meta: dict, staged: dict) -> None:
        counters = staged["simulator"]
        for key in ("n_frames", "n_episodes"):
            value = counters.get(key)
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 0:
                raise StateError(f"{where}: key 'roots.simulator.{key}': expected a non-negative integer (the "
                                 f"simulator's counter), got {value!r}")
            if meta.get(key) != value:
                raise StateError(f"{where}: key 'meta.{key}': expected {value} as the simulator's counter says, "
                                 f"got {meta.get(key)!r}")
        if staged["recorder"].get("n") != counters["n_episodes"]:
            raise StateError(f"{where}: key 'roots.recorder.n': expected {counters['n_episodes']} recorded episodes "
                             f"as the simulator's counter says, got {staged['recorder'].get('n')!r}")
        frames = _recorded_frames(sim, staged, counters["n_episodes"])
        if frames != counters["n_frames"]:
            raise StateError(f"{where}: key 'roots.simulator.n_frames': expected {frames}, the frames its recorder "
                             f"and clock say were seen, got {counters['n_frames']}")
        values = counters.get("values")
        if not isinstance(values, list) or len(values) != len(sim._values):
            raise StateError(f"{where}: key 'roots.simulator.values': expected the {len(sim._values)} signal values "
                             f"of this circuit, got {type(values).__name__} of {len(values) if isinstance(values, list) else '?'}")
        for key, want in (expected or {}).items():
            got = meta.get(key)
            if not _matches(key, got, want):
                raise StateError(f"{where}: key 'meta.{key}': expected {_short(want)} (this run's), got {_short(got)}")

    meta = load_state(folder, roots, check)
    counters = roots["simulator"]
    sim.n_frames, sim.n_episodes, sim._values = counters.n_frames, counters.n_episodes, counters.values
    return meta


def _recorded_frames(sim, staged: dict, n: int) -> int | None:
    """The frames seen in ``n`` episodes as the staged state says: the recorder's frame at the start of
    the last episode plus the clock region's frames in it (one frame per episode without a clock);
    None when the recorder's frames do not start at 0 and grow episode by episode."""
    if n == 0:
        return 0
    starts = staged["recorder"].get("_steps")
    if not isinstance(starts, np.ndarray) or starts.ndim != 1 or len(starts) < n or starts[0] != 0 \
            or (np.diff(starts[:n]) <= 0).any():
        return None
    clock = next((name for name, region in sim.regions.items() if region is sim._clock), None)
    last = staged[f"region.{clock}"].get("n_frames") if clock is not None else 1
    return int(starts[n - 1]) + last if isinstance(last, (int, np.integer)) else None


def _matches(key: str, got, want) -> bool:
    if key == "code":  # the code that saved it: one of ``want`` (a fingerprint or a list of them)
        return isinstance(got, Mapping) and any(isinstance(w, Mapping) and same_code(got, w)
                                                for w in (want if isinstance(want, list) else [want]))
    return got == want


def _short(value) -> str:
    text = json.dumps(value, sort_keys=True) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 120 else text[:117] + "..."


def params_digest(config: Mapping | None, condition: str) -> str | None:
    """The sha256 of what determines the runs of ``condition`` besides seed and steps, as the folder's
    ``config.toml`` (``config``) records it (:data:`PARAMS`); None without a record.

    Parameters
    ----------
    config : mapping or None
        The results folder's ``config.toml`` as read.
    condition : str
        The condition's name.

    Returns
    -------
    str or None
        The hex sha256 of the condition's ``world``, ``resolved_circuit`` and ``inputs`` (portable
        paths, canonical JSON); None when ``config`` has no record of the condition.
    """
    record = ((config or {}).get("conditions") or {}).get(condition)
    if not isinstance(record, Mapping):
        return None
    text = json.dumps(portable({k: record.get(k) for k in PARAMS}), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def provenance(config: Mapping | None, condition: str) -> dict:
    """What a checkpoint or saved agent of ``condition`` records beside its run's condition, number, seed
    and steps: ``params`` (:func:`params_digest` of the folder's ``config.toml``) and ``code`` (the
    running code's fingerprint, :func:`~.fingerprint.code_fingerprint`).

    Parameters
    ----------
    config : mapping or None
        The results folder's ``config.toml`` as read.
    condition : str
        The condition's name.

    Returns
    -------
    dict
        ``{"params": ..., "code": ...}``.
    """
    return {"params": params_digest(config, condition), "code": code_fingerprint()}


def agent_state(sim, meta: Mapping | None = None) -> tuple[dict, dict]:
    """A finished run's simulator as ``(body, arrays)`` (:func:`~.statefile.encode_state`), which
    the results store writes as the run's ``agent/`` folder.

    Parameters
    ----------
    sim : neurocur.scheduler.Simulator
        The simulator of a finished run.
    meta : mapping, optional
        Plain JSON kept with the state (the run's identity); the simulator's ``n_frames`` and
        ``n_episodes`` are added to it.

    Returns
    -------
    (dict, dict)
        The state's JSON body and its arrays by name.
    """
    return encode_state(_roots(sim), {**(meta or {}), "n_frames": sim.n_frames, "n_episodes": sim.n_episodes})


def write_agent(folder: Path, agent: tuple, config: Mapping | None, condition: str) -> Path:
    """Write a run's agent (:func:`agent_state`) into ``folder``, its ``meta`` completed with the run's
    :func:`provenance` (the results folder's ``config``).

    Parameters
    ----------
    folder : path
        The agent's folder (``agent/`` of the run folder being written).
    agent : tuple
        ``(body, arrays)`` as :func:`agent_state` returned them.
    config : mapping or None
        The results folder's ``config.toml`` as read.
    condition : str
        The run's condition.

    Returns
    -------
    path
        The folder written.
    """
    body, arrays = agent
    return write_state(folder, {**body, "meta": {**body["meta"], **provenance(config, condition)}}, arrays)


def checkpoint_every(steps: int, every: int | None = None) -> int:
    """Episodes between two checkpoints of a run of ``steps`` frames: ``every`` when given (0: none),
    else :data:`CHECKPOINT_EPISODES` for runs of at least :data:`CHECKPOINT_FROM_STEPS` frames and 0 below.

    Parameters
    ----------
    steps : int
        The run's length in frames.
    every : int, optional
        The interval asked for, in episodes (negative counts as 0); None: the default.

    Returns
    -------
    int
        The interval in episodes; 0: no checkpoints.
    """
    if every is not None:
        return max(0, int(every))
    return CHECKPOINT_EPISODES if steps >= CHECKPOINT_FROM_STEPS else 0


def remove_empty(top: Path) -> None:
    """Remove the temporary folders of killed saves (:func:`~.stateio.debris`) in the folders of ``top``, then
    the folders that are empty, then ``top`` when it is; links and files are left alone. Only while no run
    is in flight."""
    if top.is_symlink() or not top.is_dir():
        return
    folders = [d for d in top.iterdir() if d.is_dir() and not d.is_symlink()]
    for path in [p for d in folders for p in debris(d)]:
        remove_own(path)
    for folder in [*folders, top]:
        with contextlib.suppress(OSError):  # not empty: a run's checkpoint kept for resuming
            folder.rmdir()


def discard(folder: Path) -> None:
    """Remove the checkpoint ``folder`` and the temporary folders a killed save left beside it
    (:func:`~.stateio.debris`); a link in its place is removed, never followed, and nothing is
    removed when a folder above it is not a real folder.

    Parameters
    ----------
    folder : path
        The checkpoint folder ``OUT/checkpoints/<condition>/run-<NNN>``.
    """
    try:
        if not (real_dir(folder.parent.parent) and real_dir(folder.parent)):
            return
    except UnsafePath:
        return
    for path in [folder, *debris(folder.parent, folder.name)]:
        remove_own(path)


class Checkpoints:
    """The checkpoints of one run in ``folder``: call it after every episode (it saves every
    ``every`` episodes); :meth:`resume` continues a freshly built simulator from the last one.

    ``meta`` (the run's condition, number, seed and steps, and its :func:`provenance`: the
    condition's parameters as ``config.toml`` records them and the code) is saved with each
    checkpoint and must match on resume: a checkpoint of another run, of other parameters or of
    other code is never continued. ``required``: the checkpoints (or the agent) were asked for,
    so a simulator whose state the walker cannot save (e.g. a world holding a Python function) is
    an error when the run starts; otherwise (checkpoints on by default) the run goes on without them.

    Parameters
    ----------
    folder : path
        The run's checkpoint folder ``OUT/checkpoints/<condition>/run-<NNN>``.
    every : int
        Episodes between two saves (:func:`checkpoint_every`); 0 saves none.
    meta : mapping
        What each checkpoint records and a resume must find again (see above).
    required : bool
        True: a simulator whose state cannot be saved is an error (see above).
    """

    def __init__(self, folder, every: int, meta: Mapping, *, required: bool = False):
        self.folder = Path(folder)
        self.every = int(every)
        self.meta = dict(meta)
        self.required = required

    def __call__(self, sim) -> None:
        if self.every and sim.n_episodes % self.every == 0:
            save_simulator(sim, self.folder, self.meta)

    def resume(self, sim) -> bool:
        """Put the last checkpoint into ``sim`` (freshly built) when there is one of this run. A
        checkpoint that fails a check of :func:`restore_simulator` (unreadable, cut short, changed,
        a link, of another run, parameters or code) is discarded with one line on stderr and the
        run starts afresh; the temporary folders of a save that was killed are removed. First
        checks that ``sim``'s state can be saved at all (see ``required``)."""
        try:
            encode_state(_roots(sim))
        except StateError as exc:
            if self.required:
                raise StateError(f"condition {self.meta.get('condition')!r}: checkpoints and saved agents need "
                                 f"state the walker takes; {exc}") from None
            self.every = 0
            return False
        for path in debris(self.folder.parent, self.folder.name):
            remove_own(path)
        try:
            if not real_dir(self.folder):
                return False
            restore_simulator(sim, self.folder, self.meta)
        except (StateError, UnsafePath) as exc:
            print(f"discarded the checkpoint {self.folder}, the run starts again from its first frame: {exc}",
                  file=sys.stderr)
            self.clear()
            return False
        return True

    def clear(self) -> None:
        discard(self.folder)
