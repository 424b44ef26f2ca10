"""The step time neurocur.rl's IntrinsicReward adds to a vector-observation environment (a script, not a test).

    python benchmarks/rl_overhead.py [--env CartPole-v1] [--steps 5000] [--repeats 9] [--warmup 20000]
                                     [--models vta.novelty ...] [--clock wall|cpu]

Steps ``gym.make(env)`` with a fixed random action sequence, bare and wrapped, and prints µs per
step, the ratio wrapped / bare and the time the wrapper adds as a multiple of the bare step, for
count novelty (a pass per step), and surprise and learning progress on the slow-feature path at
their default block (``DEFAULT_FRAMES``) and at 8 steps. Each wrapper first runs ``--warmup``
steps (numba's compilation and the first modules' storage are not timed; the passes cost more as
the library grows, so the figure is that of a memory that has learned), then the bare and the
wrapped loops alternate ``--repeats`` times, and the figure is each one's median. ``--models``
keeps the cases of those models. ``--clock cpu`` times the process's CPU time instead of the wall
clock: on a loaded machine the wall clock also counts the time other processes hold the cores.

Last, the observation check alone (``ObservationCoder.check``, the slow-feature path's: the shape,
the dtype and one compiled pass over the values) on the observations of the bare loop, as a share
of count novelty's wrapped step: the count path does the same check in its context's compiled pass,
so this bounds what the check adds to it.
"""

from __future__ import annotations

import argparse
import time
import warnings

import gymnasium as gym
import numpy as np

from neurocur.rl import DEFAULT_FRAMES, IntrinsicReward, ObservationCoder

CASES = [("vta.novelty", None), ("vta.surprise", None), ("vta.learning_progress", None),
         ("vta.surprise", 8), ("vta.learning_progress", 8)]


CLOCKS = {"wall": time.perf_counter, "cpu": time.process_time}


def loop(env, actions: np.ndarray, clock=time.perf_counter) -> float:
    """Seconds per step over ``actions`` on ``clock``, resetting at each episode's end."""
    env.reset(seed=0)
    start = clock()
    for a in actions:
        _, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            env.reset()
    return (clock() - start) / len(actions)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="CartPole-v1")
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--warmup", type=int, default=20000)
    parser.add_argument("--models", nargs="+", default=sorted({model for model, _ in CASES}))
    parser.add_argument("--clock", choices=sorted(CLOCKS), default="wall")
    args = parser.parse_args(argv)
    warnings.filterwarnings("ignore", category=UserWarning)
    clock = CLOCKS[args.clock]
    bare_env = gym.make(args.env)
    rng = np.random.default_rng(0)
    actions = np.array([bare_env.action_space.sample() for _ in range(args.steps)])
    warm = np.array([bare_env.action_space.sample() for _ in range(args.warmup)])
    loop(bare_env, warm[: args.steps])
    print(f"{args.env}: µs per step ({args.clock} clock), median of {args.repeats} alternating repeats of "
          f"{args.steps} steps")
    print(f"{'model':<24}{'frames':>7}{'bare':>9}{'wrapped':>10}{'ratio':>8}{'added/bare':>12}{'modules':>9}")
    step_time = {}
    for model, frames in [case for case in CASES if case[0] in args.models]:
        wrapped = IntrinsicReward(gym.make(args.env), model, frames=frames)
        loop(wrapped, warm)
        bare, timed = [], []
        for _ in range(args.repeats):
            bare.append(loop(bare_env, actions, clock))
            timed.append(loop(wrapped, rng.permutation(actions), clock))
        b, w = np.median(bare) * 1e6, np.median(timed) * 1e6
        table = wrapped.sensory.simulator.episodes()
        modules = int(table["n_modules"].iloc[-1]) if "n_modules" in table else 0
        shown = frames or DEFAULT_FRAMES["counts" if model == "vta.novelty" else "slow_features"]
        print(f"{model:<24}{shown:>7}{b:>9.1f}{w:>10.1f}{w / b:>8.2f}{(w - b) / b:>12.2f}{modules:>9}")
        step_time[model] = w
    check = check_time(bare_env, actions, args.repeats, clock) * 1e6
    share = f", {check / step_time['vta.novelty']:.1%} of count novelty's wrapped step" if "vta.novelty" in step_time else ""
    print(f"observation check alone (ObservationCoder.check): {check:.2f} µs per observation{share}")


def check_time(env, actions: np.ndarray, repeats: int, clock) -> float:
    """Seconds per observation of ``ObservationCoder.check`` on the observations of ``env`` under
    ``actions`` (the median of ``repeats`` passes over them, on ``clock``)."""
    coder = ObservationCoder(env.observation_space, rng=np.random.default_rng(0))
    observations = [env.reset(seed=0)[0]]
    for a in actions:
        obs, _, terminated, truncated, _ = env.step(a)
        observations.append(env.reset()[0] if terminated or truncated else obs)
    check = coder.check
    check(observations[0])
    times = []
    for _ in range(repeats):
        start = clock()
        for obs in observations:
            check(obs)
        times.append((clock() - start) / len(observations))
    return float(np.median(times))


if __name__ == "__main__":
    main()
