"""The step time neurocur.rl's IntrinsicReward adds to a vector-observation environment (a script, not a test).

    python benchmarks/rl_overhead.py [--env CartPole-v1] [--steps 5000] [--repeats 9] [--warmup 20000]

Steps ``gym.make(env)`` with a fixed random action sequence, bare and wrapped, and prints µs per
step, the ratio wrapped / bare and the time the wrapper adds as a multiple of the bare step, for
count novelty (a pass per step), and surprise and learning progress on the slow-feature path at
their default block (``DEFAULT_FRAMES``) and at 8 steps. Each wrapper first runs ``--warmup``
steps (numba's compilation and the first modules' storage are not timed; the passes cost more as
the library grows, so the figure is that of a memory that has learned), then the bare and the
wrapped loops alternate ``--repeats`` times, and the figure is each one's median.
"""

from __future__ import annotations

import argparse
import time
import warnings

import gymnasium as gym
import numpy as np

from neurocur.rl import DEFAULT_FRAMES, IntrinsicReward

CASES = [("vta.novelty", None), ("vta.surprise", None), ("vta.learning_progress", None),
         ("vta.surprise", 8), ("vta.learning_progress", 8)]


def loop(env, actions: np.ndarray) -> float:
    """Seconds per step over ``actions``, resetting at each episode's end."""
    env.reset(seed=0)
    start = time.perf_counter()
    for a in actions:
        _, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            env.reset()
    return (time.perf_counter() - start) / len(actions)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="CartPole-v1")
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--warmup", type=int, default=20000)
    args = parser.parse_args(argv)
    warnings.filterwarnings("ignore", category=UserWarning)
    bare_env = gym.make(args.env)
    rng = np.random.default_rng(0)
    actions = np.array([bare_env.action_space.sample() for _ in range(args.steps)])
    warm = np.array([bare_env.action_space.sample() for _ in range(args.warmup)])
    loop(bare_env, warm[: args.steps])
    print(f"{args.env}: µs per step, median of {args.repeats} alternating repeats of {args.steps} steps")
    print(f"{'model':<24}{'frames':>7}{'bare':>9}{'wrapped':>10}{'ratio':>8}{'added/bare':>12}{'modules':>9}")
    for model, frames in CASES:
        wrapped = IntrinsicReward(gym.make(args.env), model, frames=frames)
        loop(wrapped, warm)
        bare, timed = [], []
        for _ in range(args.repeats):
            bare.append(loop(bare_env, actions))
            timed.append(loop(wrapped, rng.permutation(actions)))
        b, w = np.median(bare) * 1e6, np.median(timed) * 1e6
        table = wrapped.sensory.simulator.episodes()
        modules = int(table["n_modules"].iloc[-1]) if "n_modules" in table else 0
        shown = frames or DEFAULT_FRAMES["counts" if model == "vta.novelty" else "slow_features"]
        print(f"{model:<24}{shown:>7}{b:>9.1f}{w:>10.1f}{w / b:>8.2f}{(w - b) / b:>12.2f}{modules:>9}")


if __name__ == "__main__":
    main()
