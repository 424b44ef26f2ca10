"""Throughput of the incremental learners, in µs per sample (a script, not a test).

    python benchmarks/learners.py [--frames 20000] [--repeats 3] [--icub-frames 6000]

Streams 400-dimensional frames (two sinusoid sources mixed by a 400×2 matrix, as in
the paper's synthetic world) in episodes of 100 frames through ``IncSFA.partial_fit``
at K = 2 and K = 10 whitened dimensions with J = 2, and through ``ROCBank`` (1000
context-states, error + partial_fit per episode). One warm-up call first, so numba's
compilation is not timed; the figure is the best of a few repeats.

The iCub-size case streams 7500-pixel frames through IncSFA with the iCub experiment's
settings (K = 15, J = 2, amnesic 0.4, var_fraction 0.98, MCA η = 0.01, equal rates),
episode by episode, in the exact float64 path and the float32 path (the iCub experiment's), and prints
frames per second too. The frames are the cached iCub data set's (both contexts'
episodes, interleaved at random) if it is cached, else a synthetic stream of rank 60
(smooth random sources mixed into 7500 pixels, episodes of 80 frames); the data set is
never simulated here.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from neurocur.learn.incsfa import IncSFA

N_PIXELS = 400
EPISODE = 100


def make_stream(n_frames: int, seed: int = 0) -> np.ndarray:
    """Frames in [0, 1] from two sinusoids (1 and 24 cycles per 1000 steps)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames)
    sources = np.stack([np.sin(2 * np.pi * t / 1000), np.sin(2 * np.pi * 24 * t / 1000 + 1.0)], axis=1)
    mixing = rng.uniform(0.0, 1.0, (2, N_PIXELS))
    frames = sources @ mixing
    return (frames - frames.min()) / np.ptp(frames)


def best_time(fn, repeats: int) -> float:
    """Smallest wall time of ``repeats`` calls of ``fn``, in seconds."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def bench_incsfa(frames: np.ndarray, n_pca: int, repeats: int) -> float:
    episodes = [frames[start : start + EPISODE] for start in range(0, len(frames), EPISODE)]
    return bench_episodes(IncSFA(n_components=2, n_pca=n_pca, random_state=0), episodes, repeats)


def bench_episodes(model: IncSFA, episodes: list[np.ndarray], repeats: int) -> float:
    """µs per frame of ``model.partial_fit`` over ``episodes``, after a warm-up episode."""
    model.partial_fit(episodes[0])  # warm-up: compile

    def run():
        for episode in episodes:
            model.partial_fit(episode)

    return best_time(run, repeats) / sum(len(e) for e in episodes) * 1e6


def icub_episodes(n_frames: int, seed: int = 0) -> tuple[list[np.ndarray], str]:
    """About ``n_frames`` 7500-pixel frames in episodes, and where they come from."""
    from neurocur.contexts.icub import ICubParams, ICubWorld, cache_file

    rng = np.random.default_rng(seed)
    if cache_file(ICubParams()).exists():
        world = ICubWorld.from_params(ICubParams())
        pool = [np.ascontiguousarray(e.frames) for c in range(2) for e in world.episodes(c)]
        episodes, total = [], 0
        while total < n_frames:
            episodes.append(pool[rng.integers(len(pool))])
            total += len(episodes[-1])
        return episodes, "cached iCub frames"
    steps = rng.standard_normal((n_frames, 60)).cumsum(axis=0) / np.sqrt(np.arange(1, n_frames + 1))[:, None]
    frames = 0.5 + (steps @ rng.standard_normal((60, 7500))) / 60
    return [frames[start : start + 80] for start in range(0, n_frames, 80)], "synthetic rank-60 stream"


def bench_icub_size(n_frames: int, repeats: int) -> list[tuple[str, float]]:
    episodes, source = icub_episodes(n_frames)
    settings = dict(amnesic=0.4, var_fraction=0.98, mca_rate=0.01, mca_rates="equal", random_state=0)
    return [(f"IncSFA.partial_fit, D=7500, K=15, J=2, {dtype} ({source})",
             bench_episodes(IncSFA(2, 15, dtype=dtype, **settings), episodes, repeats))
            for dtype in ("float64", "float32")]


def bench_roc(n_frames: int, repeats: int) -> float | None:
    try:
        from neurocur.learn.roc import ROCBank
    except ImportError:
        return None
    rng = np.random.default_rng(1)
    n_states = 1000
    states = np.arange(n_frames, dtype=np.int64) % n_states
    features = rng.standard_normal((n_frames, 2))
    bank = ROCBank(n_states, 2)
    bank.partial_fit(states[:EPISODE], features[:EPISODE])  # warm-up: compile
    bank.error(states[:EPISODE], features[:EPISODE])

    def run():
        for start in range(0, n_frames, EPISODE):
            s, y = states[start : start + EPISODE], features[start : start + EPISODE]
            bank.error(s, y)
            bank.partial_fit(s, y)

    return best_time(run, repeats) / n_frames * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20_000, help="frames per timed run")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--icub-frames", type=int, default=6000, help="frames per timed run of the iCub-size case")
    args = parser.parse_args()
    frames = make_stream(args.frames)
    rows = [
        ("IncSFA.partial_fit, D=400, K=2, J=2", bench_incsfa(frames, 2, args.repeats)),
        ("IncSFA.partial_fit, D=400, K=10, J=2", bench_incsfa(frames, 10, args.repeats)),
        ("ROCBank error + partial_fit, 1000 states, J=2", bench_roc(args.frames, args.repeats)),
        *bench_icub_size(args.icub_frames, args.repeats),
    ]
    width = max(len(name) for name, _ in rows)
    print(f"{'learner':<{width}}  µs/sample   samples/s")
    for name, us in rows:
        figure = "n/a (neurocur.learn.roc missing)" if us is None else f"{us:9.2f}  {1e6 / us:10,.0f}"
        print(f"{name:<{width}}  {figure}")


if __name__ == "__main__":
    main()
