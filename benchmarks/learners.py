"""Throughput of the incremental learners, in µs per sample (a script, not a test).

    python benchmarks/learners.py

Streams 400-dimensional frames (two sinusoid sources mixed by a 400×2 matrix, as in
the paper's synthetic world) in episodes of 100 frames through ``IncSFA.partial_fit``
at K = 2 and K = 10 whitened dimensions with J = 2, and through ``ROCBank`` (1000
context-states, error + partial_fit per episode). One warm-up call first, so numba's
compilation is not timed; the figure is the best of a few repeats.
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
    model = IncSFA(n_components=2, n_pca=n_pca, random_state=0)
    model.partial_fit(frames[:EPISODE])  # warm-up: compile

    def run():
        for start in range(0, len(frames), EPISODE):
            model.partial_fit(frames[start : start + EPISODE])

    return best_time(run, repeats) / len(frames) * 1e6


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
    args = parser.parse_args()
    frames = make_stream(args.frames)
    rows = [
        ("IncSFA.partial_fit, D=400, K=2, J=2", bench_incsfa(frames, 2, args.repeats)),
        ("IncSFA.partial_fit, D=400, K=10, J=2", bench_incsfa(frames, 10, args.repeats)),
        ("ROCBank error + partial_fit, 1000 states, J=2", bench_roc(args.frames, args.repeats)),
    ]
    width = max(len(name) for name, _ in rows)
    print(f"{'learner':<{width}}  µs/sample")
    for name, us in rows:
        figure = "n/a (neurocur.learn.roc missing)" if us is None else f"{us:9.2f}"
        print(f"{name:<{width}}  {figure}")


if __name__ == "__main__":
    main()
