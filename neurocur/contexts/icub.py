"""The simulated iCub world (paper section 4.2): two object contexts seen by a fixed eye.

The robot's head is fixed; its eye camera gives grayscale 75×100 frames. The right
arm babbles with a single shoulder joint over 20 quantized states (the context-state):
each frame the joint moves to an adjacent state (a ±1 random walk, reflecting at the
ends), so the outstretched hand eventually hits the single object on the table:

- ``"topple"``: a cup that the hand tips over, much the same way every time;
- ``"roll"``: a ball that the fingertip strikes glancingly, so it rolls off in a
  direction that differs from episode to episode (its placement along the arm's radius
  is drawn per episode within ``±ball_jitter``; see :mod:`.icub_scene`).

An episode starts with the arm at ``start_state`` and the object in its place; it
ends ``post_contact`` frames after the first hand–object contact, never before
``min_frames`` and at most at ``max_frames`` frames (50–250 in the paper).

Episodes are simulated with MuJoCo and rendered offscreen once, deterministically from
a seed, and cached on disk as an ``.npz`` keyed by a hash of every generator parameter
and the MuJoCo version; a run (:meth:`World.reset`) then draws episodes from that pool
in a per-run random order. MuJoCo is imported lazily, so ``import neurocur`` does not
need it. The GL backend is ``MUJOCO_GL`` (default ``"egl"``, which works with Mesa's
software renderer; ``"osmesa"`` needs the system's libOSMesa).

Learning difficulty: :func:`omega_episodes` is Ω (eq 15/40) of a list of episodes with
the derivative taken within episodes only, after a PCA keeping 98 % of the variance
(the paper's 0.9982 for topple and 0.9988 for the rolling ball).
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

from ..learn._validation import check_fraction, check_positive_int
from ..learn.omega import omega
from .base import Episode, World
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
    import mujoco

    return mujoco


@dataclass(frozen=True)
class EpisodeParams:
    """The episode protocol; every field enters the cache key."""

    start_state: int = 0
    post_contact: int = 40
    min_frames: int = 50
    max_frames: int = 250
    #: simulated seconds between two frames (one babbling action per frame)
    frame_time: float = 0.08
    #: simulated seconds to let the scene settle before the first frame
    settle_time: float = 0.3

    def __post_init__(self):
        for name in ("post_contact", "min_frames", "max_frames"):
            check_positive_int(getattr(self, name), name)
        if not 50 <= self.min_frames <= self.max_frames <= 250:
            raise ValueError(
                f"episode lengths must satisfy 50 <= min_frames <= max_frames <= 250; "
                f"got min_frames={self.min_frames}, max_frames={self.max_frames}"
            )
        if self.frame_time <= 0 or self.settle_time < 0:
            raise ValueError("frame_time must be > 0 and settle_time >= 0")


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
        moves = rng.choice(np.array([-1, 1]), size=p.max_frames)
        frames, states, positions = [], [], []
        contact, length = -1, p.max_frames
        for t in range(p.max_frames):
            if t > 0:
                state = _reflect(state + moves[t], len(self.angles))
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
    code = "import sys; from neurocur.contexts.icub import _run_job; _run_job(sys.argv[1])"
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


def cache_key(scene: SceneParams, protocol: EpisodeParams, n_episodes: int, seed: int) -> str:
    """Hash of everything that determines the episodes, including the MuJoCo version."""
    spec = {
        "format": _CACHE_FORMAT,
        "mujoco": _mujoco().__version__,
        "frame_shape": FRAME_SHAPE,
        "scene": asdict(scene),
        "protocol": asdict(protocol),
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


class ICubWorld(World):
    """Two object contexts, ``"topple"`` (cup) and ``"roll"`` (ball), seen by the iCub's eye.

    ``n_episodes`` episodes per context are simulated once from ``seed`` and cached under
    ``cache_dir`` (default :func:`default_cache_dir`); a later construction with the same
    parameters reads the cache. :meth:`reset` draws a per-run random order of each
    context's pool, and :meth:`step` returns that context's next episode (a fresh order
    is drawn each time a context's pool is used up). The context-state is the shoulder
    joint's state (0..19). ``last_info`` (also merged into the ``info`` dicts) names the
    pool index and the contact frame of the episode just returned.
    """

    context_names = OBJECTS
    source_names = OBJECTS
    frame_shape = FRAME_SHAPE

    def __init__(
        self,
        n_episodes: int = 70,
        seed: int = 0,
        cache_dir=None,
        *,
        scene: SceneParams | None = None,
        protocol: EpisodeParams | None = None,
        n_jobs: int = 2,
    ) -> None:
        super().__init__()
        self.n_episodes = check_positive_int(n_episodes, "n_episodes")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ValueError(f"seed must be a non-negative int; got {seed!r}")
        self.seed = int(seed)
        self.scene = scene or SceneParams()
        self.protocol = protocol or EpisodeParams()
        self.n_states = self.scene.n_states
        if not 0 <= self.protocol.start_state < self.n_states:
            raise ValueError(f"protocol.start_state must be in [0, {self.n_states}); got {self.protocol.start_state}")
        n_jobs = check_positive_int(n_jobs, "n_jobs")
        key = cache_key(self.scene, self.protocol, self.n_episodes, self.seed)
        self.cache_path = Path(cache_dir or default_cache_dir()).expanduser() / f"icub-{key}.npz"
        if self.cache_path.exists():
            self.pools = _load(self.cache_path)
        else:
            self.pools = _generate(self.scene, self.protocol, self.n_episodes, self.seed, n_jobs)
            _save(self.cache_path, self.pools)
        self.last_info: dict = {}
        self._reset()

    def reset(self, *, seed=None, context: int = 0):
        ep, info = super().reset(seed=seed, context=context)
        return ep, {**info, **self.last_info}

    def step(self, context: int):
        ep, reward, terminated, truncated, info = super().step(context)
        return ep, reward, terminated, truncated, {**info, **self.last_info}

    def _reset(self) -> None:
        self._order = [np.empty(0, dtype=np.int64) for _ in OBJECTS]
        self._cursor = [0] * len(OBJECTS)

    def _visit(self, context: int) -> Episode:
        if self._cursor[context] >= len(self._order[context]):
            self._order[context] = self.np_random.permutation(self.n_episodes)
            self._cursor[context] = 0
        index = int(self._order[context][self._cursor[context]])
        self._cursor[context] += 1
        self.last_info = {
            "context": context,
            "episode_index": index,
            "contact_frame": self.contact_frame(context, index),
        }
        return self.episode(context, index)

    def _pool(self, context, index) -> tuple[EpisodePool, slice]:
        context = self._check_context(context)
        if not (isinstance(index, (int, np.integer)) and 0 <= index < self.n_episodes):
            raise ValueError(f"episode_index must be an int in [0, {self.n_episodes}); got {index!r}")
        pool = self.pools[OBJECTS[context]]
        return pool, pool.rows(int(index))

    def episode(self, context: int, episode_index: int) -> Episode:
        """Episode ``episode_index`` of the cached pool of ``context`` (frames as float64 in [0, 1])."""
        pool, rows = self._pool(context, episode_index)
        frames = pool.frames[rows].reshape(-1, self.n_pixels) / 255.0
        return Episode(frames=frames, states=pool.states[rows].copy(), context=int(context))

    def object_positions(self, context: int, episode_index: int) -> np.ndarray:
        """Ground truth: the object's centre (x, y, z) in metres at each frame, (T, 3)."""
        pool, rows = self._pool(context, episode_index)
        return pool.positions[rows].copy()

    def displacement(self, context: int, episode_index: int) -> np.ndarray:
        """Ground truth: distance (m) of the object's centre from its start, per frame, (T,)."""
        pos = self.object_positions(context, episode_index)
        return np.linalg.norm(pos - pos[0], axis=1)

    def contact_frame(self, context: int, episode_index: int) -> int:
        """Frame of the first hand–object contact, or -1 if the hand never touched the object."""
        pool, _ = self._pool(context, episode_index)
        return int(pool.contact[episode_index])

    def episodes(self, context: int) -> list[Episode]:
        """Every cached episode of ``context``, in pool order."""
        return [self.episode(context, i) for i in range(self.n_episodes)]


def _principal_basis(U: np.ndarray, var_fraction: float, rng: np.random.Generator) -> np.ndarray:
    """Leading principal directions of centred ``U`` that keep ``var_fraction`` of its variance.

    Randomized subspace iteration (Halko, Martinsson & Tropp 2011), doubling the sketch
    until the kept eigenvalues reach the fraction of the exact total variance ``‖U‖²``.
    """
    total = np.einsum("ij,ij->", U, U)
    k = 64
    while True:
        k = min(k, *U.shape)
        Q = np.linalg.qr(U.T @ (U @ rng.standard_normal((U.shape[1], k + 10))))[0]
        for _ in range(3):
            Q = np.linalg.qr(U.T @ (U @ Q))[0]
        _, sv, Vt = np.linalg.svd(U @ Q, full_matrices=False)
        frac = np.cumsum(sv**2) / total
        if frac[-1] >= var_fraction or k == min(U.shape):
            n = int(np.searchsorted(frac, var_fraction) + 1)
            return Q @ Vt[:n].T
        k *= 2


def pca_reduce(episodes, var_fraction: float = 0.98) -> list[np.ndarray]:
    """Project every episode onto the principal directions of all their frames together.

    The frames of all episodes (each an :class:`Episode` or a (T, D) array) are centred
    together and reduced to the leading directions that keep ``var_fraction`` of the
    variance (as CCIPCA does in section 4.2.1). Returns one (T, n) block per episode.
    """
    var_fraction = check_fraction(var_fraction, "var_fraction")
    blocks = [np.asarray(e.frames if isinstance(e, Episode) else e, dtype=np.float64) for e in episodes]
    if not blocks or any(b.ndim != 2 or len(b) < 2 for b in blocks):
        raise ValueError("episodes must be a non-empty list of (T, D) blocks with T >= 2")
    X = np.concatenate(blocks)
    U = X - X.mean(axis=0)
    Y = U @ _principal_basis(U, var_fraction, np.random.default_rng(0))
    return np.split(Y, np.cumsum([len(b) for b in blocks])[:-1])


def omega_episodes(episodes, eta: float = 0.01, *, var_fraction: float = 0.98, rank_tol: float = 1e-10) -> float:
    """Ω (eqs 15, 40) of a set of episodes, the derivative taken within episodes only.

    The episodes are reduced by :func:`pca_reduce`, then :func:`~neurocur.learn.omega.omega`
    whitens them together and differences inside each episode.
    """
    reduced = pca_reduce(episodes, var_fraction)
    starts = np.cumsum([0] + [len(r) for r in reduced[:-1]])
    return omega(np.concatenate(reduced), eta, rank_tol=rank_tol, starts=starts)
