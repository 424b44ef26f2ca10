"""Speed of fitting on one paper-size data set: a cached likelihood evaluation and a 3-parameter fit.

    python benchmarks/fit_speed.py [--episodes 2000]

One data set of ``--episodes`` engage/disengage decisions (2000: about 3.5e5 frames, the paper's run
length) is simulated in the synthetic world by the adaptive-gain LC's circuit (experiment lc_models,
run 0's seed) and replayed once (the learning part). Then it prints:

- one likelihood evaluation of the softmax LC's gain on its cached replay (vectorised; target <= 10 ms),
  the median of 200;
- a maximum-likelihood fit of 3 decision parameters of the adaptive-gain LC (gain_tonic, gain_phasic,
  slope_short; stepped, no closed form across theta in one array) from 2 starts, without and with
  the profile-likelihood intervals (target <= 60 s on 2 cores for the fit).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from neurocur.experiments import load_experiment
from neurocur.fit.mle import fit_ml
from neurocur.fit.recovery import simulate
from neurocur.fit.replay import Replay


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=2000)
    args = parser.parse_args()
    exp = load_experiment("lc_models")
    seed = exp.run_seed(0)

    softmax = exp.conditions["softmax"]
    behaviour, episodes = simulate(softmax, {}, seed, args.episodes)
    started = time.perf_counter()
    replay = Replay(softmax.circuit, softmax.make_world(), seed, behaviour, fitted=["LC.gain"])
    print(f"data set: {args.episodes} decisions, {int(episodes['n_frames'].sum())} frames; "
          f"the replay's learning part {time.perf_counter() - started:.1f} s (once per data set)")
    times = []
    for g in np.linspace(0.05, 3.0, 200):
        t = time.perf_counter()
        replay.loglik({"LC.gain": float(g)})
        times.append(time.perf_counter() - t)
    print(f"one likelihood evaluation (softmax gain, cached replay): median {1e3 * np.median(times):.2f} ms "
          f"(target <= 10 ms)")

    adaptive = exp.conditions["adaptive_gain"]
    behaviour, _ = simulate(adaptive, {}, seed, args.episodes)
    keys = ["LC.gain_tonic", "LC.gain_phasic", "LC.slope_short"]
    replay = Replay(adaptive.circuit, adaptive.make_world(), seed, behaviour, fitted=keys)
    bounds = {"LC.gain_tonic": (0.0, 2.0), "LC.gain_phasic": (2.0, 20.0), "LC.slope_short": (0.1, 5.0)}
    t = time.perf_counter()
    replay.loglik({})
    print(f"one likelihood evaluation (adaptive gain, stepped): {1e3 * (time.perf_counter() - t):.1f} ms")
    for ci in (None, 0.95):
        t = time.perf_counter()
        fit = fit_ml(replay, bounds, starts=2, ci=ci)
        what = "with profile intervals" if ci else "estimates only"
        print(f"fit of 3 decision parameters ({what}): {time.perf_counter() - t:.1f} s (target <= 60 s); "
              + ", ".join(f"{k} = {v:.3g}" for k, v in fit.estimate.items()) + " (truth: 0.5, 10, 1)")


if __name__ == "__main__":
    main()
