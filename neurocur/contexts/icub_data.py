"""The simulated iCub episode data set (paper section 4.2): MuJoCo simulation, rendering, cache.

Episodes are simulated with MuJoCo and rendered offscreen once, deterministically from a
seed, and cached on disk as an ``.npz`` keyed by a hash of every generator parameter and
the MuJoCo version (:func:`cache_key`). MuJoCo is imported lazily, so ``import neurocur``
does not need it. The GL backend is ``MUJOCO_GL`` (default ``"egl"``, which works with
Mesa's software renderer; ``"osmesa"`` needs the system's libOSMesa). The world that
draws episodes from the data set is :class:`neurocur.contexts.icub.ICubWorld`.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import subprocess
import sys
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..config import ConfigError, check_params, describe, extra, param
from .icub_scene import OBJECTS, SceneParams, scene_xml

FRAME_SHAPE = (75, 100)
_CACHE_FORMAT = 1
_LUMA = np.array([0.299, 0.587, 0.114])


def _mujoco():
    """Import MuJoCo with an offscreen GL backend chosen before the first import."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    backend = os.environ["MUJOCO_GL"].lower()
    if backend in ("egl", "osmesa"):
        os.environ.setdefault("PYOPENGL_PLATFORM", backend)
    with extra("icub", "the iCub world"):
        import mujoco

    return mujoco


@dataclass(frozen=True)
class EpisodeParams:
    """The episode protocol; every field enters the cache key."""

    start_state: int = param(0, int, low=0, doc="arm state at the start of an episode")
    post_contact: int = param(40, int, low=1, doc="frames after the first hand-object contact")
    min_frames: int = param(50, int, low=50, high=250, doc="shortest episode (50-250 in the paper)")
    max_frames: int = param(250, int, low=50, high=250, doc="longest episode")
    frame_time: float = param(0.08, float, low=0.0, low_open=True,
                              doc="simulated seconds between two frames (one babbling action per frame)")
    settle_time: float = param(0.3, float, low=0.0, doc="simulated seconds to let the scene settle first")
    steps_per_frame: int = param(1, int, low=1, doc="babbling actions (of frame_time each) between two observed "
                                 "frames: the camera's frame rate against the arm's control rate")

    def __post_init__(self):
        check_params(self)
        if self.min_frames > self.max_frames:
            raise ConfigError(type(self).__name__, "min_frames", f"at most max_frames = {self.max_frames}",
                              describe(self.min_frames))


@dataclass
class EpisodePool:
    """All cached episodes of one context, frames kept as 8-bit gray to save memory."""

    frames: np.ndarray  # uint8 (total_frames, 75, 100)
    states: np.ndarray  # int64 (total_frames,)
    positions: np.ndarray  # float64 (total_frames, 3): object centre per frame
    offsets: np.ndarray  # int64 (n_episodes + 1,): episode i is rows offsets[i]:offsets[i+1]
    contact: np.ndarray  # int64 (n_episodes,): frame of first hand–object contact, -1 if none
    bounds: list = field(init=False)

    def __post_init__(self):
        self.bounds = list(zip(self.offsets[:-1], self.offsets[1:]))

    def __len__(self) -> int:
        return len(self.contact)

    def rows(self, i: int) -> slice:
        a, b = self.bounds[i]
        return slice(int(a), int(b))


class _Simulation:
    """One scene (model, data, renderer) that plays episodes of one object."""

    def __init__(self, obj: str, scene: SceneParams, protocol: EpisodeParams):
        mj = _mujoco()
        self.mj, self.obj, self.scene, self.protocol = mj, obj, scene, protocol
        self.model = mj.MjModel.from_xml_string(scene_xml(obj, scene, height=FRAME_SHAPE[0], width=FRAME_SHAPE[1]))
        self.data = mj.MjData(self.model)
        self.renderer = mj.Renderer(self.model, *FRAME_SHAPE)
        for flag in (mj.mjtRndFlag.mjRND_SHADOW, mj.mjtRndFlag.mjRND_REFLECTION):
            self.renderer.scene.flags[flag] = False
        self.angles = scene.state_angles()
        self.object_id = self.model.body("object").id
        self._pair = sorted((self.model.body("arm").id, self.object_id))
        self.qpos_arm = self.model.joint("shoulder").qposadr[0]
        self.qpos_object = self.model.joint("object").qposadr[0]
        self.substeps = max(1, round(protocol.frame_time / scene.timestep))
        self.settle_steps = round(protocol.settle_time / scene.timestep)

    def _touching(self) -> bool:
        """Whether the hand (any arm geom) is in contact with the object now."""
        n = self.data.ncon
        if n == 0:
            return False
        bodies = np.sort(self.model.geom_bodyid[self.data.contact.geom[:n]], axis=1)
        return bool(np.any((bodies[:, 0] == self._pair[0]) & (bodies[:, 1] == self._pair[1])))

    def _frame(self) -> np.ndarray:
        self.renderer.update_scene(self.data, camera="eye")
        return np.rint(self.renderer.render() @ _LUMA).astype(np.uint8)

    def _place_object(self, rng: np.random.Generator) -> None:
        """Per-episode variation: the ball's radial placement within ``±ball_jitter``."""
        if self.obj == "roll":
            jitter = self.scene.ball_jitter
            self.data.qpos[self.qpos_object : self.qpos_object + 2] = self.scene.object_position(
                "roll", rng.uniform(-jitter, jitter)
            )

    def play(self, rng: np.random.Generator):
        """Simulate one episode; returns ``(frames uint8, states, positions, contact_frame)``."""
        mj, m, d, p = self.mj, self.model, self.data, self.protocol
        mj.mj_resetData(m, d)
        self._place_object(rng)
        state = p.start_state
        d.qpos[self.qpos_arm] = d.ctrl[0] = self.angles[state]
        mj.mj_forward(m, d)
        for _ in range(self.settle_steps):
            mj.mj_step(m, d)
        k = p.steps_per_frame  # frame t > 0 follows the actions moves[(t - 1) k + 1 .. t k]
        moves = rng.choice(np.array([-1, 1]), size=p.max_frames * k)
        frames, states, positions = [], [], []
        contact, length = -1, p.max_frames
        for t in range(p.max_frames):
            for move in moves[(t - 1) * k + 1 : t * k + 1] if t > 0 else ():
                state = _reflect(state + move, len(self.angles))
                d.ctrl[0] = self.angles[state]
                for _ in range(self.substeps):
                    mj.mj_step(m, d)
                    if contact < 0 and self._touching():
                        contact = t
                        length = min(max(t + 1 + p.post_contact, p.min_frames), p.max_frames)
            frames.append(self._frame())
            states.append(state)
            positions.append(d.xpos[self.object_id].copy())
            if t + 1 >= length:
                break
        return np.array(frames), np.array(states, dtype=np.int64), np.array(positions), contact

    def close(self) -> None:
        self.renderer.close()


def _reflect(state: int, n_states: int) -> int:
    """Keep a ±1 random-walk step inside ``0..n_states-1`` by reflecting it at the ends."""
    if state < 0:
        return 1
    if state >= n_states:
        return n_states - 2
    return int(state)


def _play_chunk(obj: str, scene: SceneParams, protocol: EpisodeParams, seeds) -> list:
    """Simulate the episodes of ``obj`` seeded by ``seeds`` with one scene."""
    sim = _Simulation(obj, scene, protocol)
    try:
        return [sim.play(np.random.default_rng(s)) for s in seeds]
    finally:
        sim.close()


def _run_job(path: str) -> None:
    """Worker-process entry point: play the chunks pickled in ``path``, pickle the results back."""
    with open(path, "rb") as fh:
        chunks = pickle.load(fh)
    results = [_play_chunk(*chunk) for chunk in chunks]
    with open(path + ".out", "wb") as fh:
        pickle.dump(results, fh, protocol=pickle.HIGHEST_PROTOCOL)


def _run_jobs(jobs: list) -> list:
    """Run each job (a list of :func:`_play_chunk` argument tuples) in its own Python process.

    Plain subprocesses rather than ``multiprocessing``: each worker gets a fresh GL context,
    and the caller's ``__main__`` is never re-imported (no ``if __name__ == "__main__"`` needed).
    """
    code = "import sys; from neurocur.contexts.icub_data import _run_job; _run_job(sys.argv[1])"
    with tempfile.TemporaryDirectory(prefix="neurocur-icub-") as tmp:
        procs = []
        for j, job in enumerate(jobs):
            path = os.path.join(tmp, f"job{j}.pkl")
            with open(path, "wb") as fh:
                pickle.dump(job, fh, protocol=pickle.HIGHEST_PROTOCOL)
            procs.append((path, subprocess.Popen([sys.executable, "-c", code, path], stderr=subprocess.PIPE)))
        results = []
        for path, proc in procs:
            _, err = proc.communicate()
            if proc.returncode != 0:
                raise RuntimeError(f"iCub episode worker failed (exit {proc.returncode}):\n{err.decode(errors='replace')}")
            with open(path + ".out", "rb") as fh:
                results.append(pickle.load(fh))
    return results


def _pool(results: list) -> EpisodePool:
    lengths = [len(r[0]) for r in results]
    return EpisodePool(
        frames=np.concatenate([r[0] for r in results]),
        states=np.concatenate([r[1] for r in results]),
        positions=np.concatenate([r[2] for r in results]),
        offsets=np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
        contact=np.array([r[3] for r in results], dtype=np.int64),
    )


def _generate(scene: SceneParams, protocol: EpisodeParams, n_episodes: int, seed: int, n_jobs: int) -> dict:
    """Simulate ``n_episodes`` of every object; episode i of an object always gets the same seed.

    Each object's episodes are split into ``n_jobs`` contiguous chunks, and worker process
    j plays chunk j of every object; the result does not depend on ``n_jobs``.
    """
    roots = np.random.SeedSequence(seed).spawn(len(OBJECTS))
    seeds = {obj: root.spawn(n_episodes) for obj, root in zip(OBJECTS, roots)}
    splits = np.array_split(np.arange(n_episodes), min(n_jobs, n_episodes))
    jobs = [[(obj, scene, protocol, [seeds[obj][i] for i in chunk]) for obj in OBJECTS] for chunk in splits]
    done = [[_play_chunk(*c) for c in job] for job in jobs] if len(jobs) == 1 else _run_jobs(jobs)
    return {obj: _pool([ep for job in done for ep in job[k]]) for k, obj in enumerate(OBJECTS)}


def default_cache_dir() -> Path:
    """``$NEUROCUR_CACHE/icub`` if that variable is set, else ``~/.cache/neurocur/icub``."""
    root = os.environ.get("NEUROCUR_CACHE")
    return (Path(root) if root else Path.home() / ".cache" / "neurocur") / "icub"


#: fields added after the cache's first format, with their defaults: at its default such a field is
#: left out of the key, so that a data set made before it existed keeps its key and cache file
_LATER_FIELDS = {"arm": "primitive", "arm_contrast": 1.0, "steps_per_frame": 1}


def _key_fields(params) -> dict:
    """Every field of ``params`` (a scene or a protocol) but those of :data:`_LATER_FIELDS` at their defaults."""
    return {k: v for k, v in asdict(params).items() if k not in _LATER_FIELDS or v != _LATER_FIELDS[k]}


def _scene_key(scene: SceneParams) -> dict:
    """The scene's part of the cache key (:func:`_key_fields`); the iCub's arm adds the version of
    the package its meshes come from."""
    fields = _key_fields(scene)
    if scene.arm != "primitive":
        from importlib.metadata import version

        fields["icub_models"] = version("icub-models")
    return fields


def cache_key(scene: SceneParams, protocol: EpisodeParams, n_episodes: int, seed: int) -> str:
    """Hash of everything that determines the episodes, including the MuJoCo version."""
    spec = {
        "format": _CACHE_FORMAT,
        "mujoco": _mujoco().__version__,
        "frame_shape": FRAME_SHAPE,
        "scene": _scene_key(scene),
        "protocol": _key_fields(protocol),
        "n_episodes": n_episodes,
        "seed": seed,
    }
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:20]


_POOL_FIELDS = ("frames", "states", "positions", "offsets", "contact")


def _save(path: Path, pools: dict) -> None:
    """Write the pools atomically (a temporary file renamed into place)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {f"{obj}_{f}": getattr(pool, f) for obj, pool in pools.items() for f in _POOL_FIELDS}
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".npz.tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _load(path: Path) -> dict:
    with np.load(path) as z:
        return {obj: EpisodePool(**{f: z[f"{obj}_{f}"] for f in _POOL_FIELDS}) for obj in OBJECTS}


def cached(path: Path, make) -> dict:
    """The pools cached at ``path``, else ``make()``'s, written there first."""
    if path.exists():
        return _load(path)
    pools = make()
    _save(path, pools)
    return pools


def blurred(pools: dict, sigma: float, chunk: int = 512) -> dict:
    """The pools with every frame blurred by a Gaussian of standard deviation ``sigma`` pixels (as
    a camera's optics would; edges repeat the border pixel), rounded back to 8-bit gray. The
    frames are filtered ``chunk`` at a time, so the float copy stays small."""
    from scipy.ndimage import gaussian_filter  # here: only a blurred world needs it

    out = {}
    for obj, pool in pools.items():
        frames = np.empty_like(pool.frames)
        for a in range(0, len(frames), chunk):
            block = gaussian_filter(pool.frames[a:a + chunk].astype(np.float32), sigma=(0.0, sigma, sigma), mode="nearest")
            frames[a:a + chunk] = np.clip(np.rint(block), 0, 255)
        out[obj] = EpisodePool(frames, pool.states, pool.positions, pool.offsets, pool.contact)
    return out
