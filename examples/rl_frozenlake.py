"""
# FrozenLake: curiosity bonuses

A tabular Q-learner on a sparse-reward FrozenLake, with neurocur's VTA models as its curiosity.

The task: FrozenLake 8x8, not slippery, its goal (reward 1, the only reward) 14 steps from the
start, its holes ending the episode, 200 steps at most; the observation is the agent's (row,
column) scaled to [0, 1], a vector Box, so that the wrapper's grid of 8 x 8 contexts is its cells.
The agent: Q-learning with epsilon-greedy actions (ties broken at random) on the wrapped reward,
the environment's plus the bonus. Four conditions, paired by seed: no bonus, count novelty
(``vta.novelty``), surprise (``vta.surprise``) and learning progress (``vta.learning_progress``),
each VTA model with its defaults and ``scale=0.1``; count novelty counts every step (``frames=1``,
the only pass its counts path takes), the slow-feature path takes blocks of 8 steps.

    PYTHONPATH=. python examples/rl_frozenlake.py                      # the comparison (docs/hypotheses.md, 12)
    PYTHONPATH=. python examples/rl_frozenlake.py --seeds 2 --steps 3000   # a quick look

The documentation gallery runs 3 seeds x 10 000 steps (seconds; too few to compare the bonuses).
The figure shows each seed's steps until it first reached the goal (grey lines join a seed's four
conditions) and their mean; the dotted line is the budget, reached by seeds that never found the goal.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import numpy as np

from neurocur.rl import IntrinsicReward

CONDITIONS = {"no bonus": None, "count novelty": "vta.novelty", "surprise": "vta.surprise",
              "learning progress": "vta.learning_progress"}
SCALE, FRAMES = 0.1, 8   # FRAMES: steps per pass on the slow-feature path; count novelty counts every step


class Coordinates(gym.ObservationWrapper):
    """FrozenLake's cell index as (row, column) / (size - 1): a vector Box observation."""

    def __init__(self, env):
        super().__init__(env)
        self.size = env.unwrapped.ncol
        self.observation_space = gym.spaces.Box(0.0, 1.0, (2,), np.float64)

    def observation(self, cell):
        return np.array(divmod(int(cell), self.size), dtype=np.float64) / (self.size - 1)


def make_env(model: str | None):
    env = Coordinates(gym.make("FrozenLake-v1", map_name="8x8", is_slippery=False))
    if model is None:
        return env
    frames = 1 if model == "vta.novelty" else FRAMES   # the counts path takes a pass per step only
    return IntrinsicReward(env, model, scale=SCALE, frames=frames, overrides={"EC.n_pca": 2})


def run(model: str | None, seed: int, steps: int, *, alpha=0.5, gamma=0.99, epsilon=0.1) -> dict:
    """One run: Q-learning for ``steps`` steps. Returns the step at which the goal was first
    reached (``steps`` if never) and whether the greedy policy reaches it at the end."""
    env, rng = make_env(model), np.random.default_rng(seed)
    size = env.unwrapped.ncol
    q = np.zeros((size * size, env.action_space.n))
    cell = lambda obs: int(round(obs[0] * (size - 1))) * size + int(round(obs[1] * (size - 1)))  # noqa: E731
    greedy = lambda s: int(rng.choice(np.flatnonzero(q[s] == q[s].max())))  # noqa: E731
    s, first_goal = cell(env.reset(seed=seed)[0]), steps
    for t in range(steps):
        a = int(rng.integers(env.action_space.n)) if rng.random() < epsilon else greedy(s)
        obs, reward, terminated, truncated, info = env.step(a)
        s2 = cell(obs)
        q[s, a] += alpha * (reward + gamma * (not terminated) * q[s2].max() - q[s, a])
        if info.get("extrinsic_reward", reward) > 0 and first_goal == steps:
            first_goal = t + 1
        s = cell(env.reset()[0]) if terminated or truncated else s2
    return {"first_goal": first_goal, "greedy_success": _greedy_success(q, size, seed)}


def _greedy_success(q: np.ndarray, size: int, seed: int) -> bool:
    """Whether the greedy policy of ``q`` (first best action) reaches the goal of the bare task."""
    env = Coordinates(gym.make("FrozenLake-v1", map_name="8x8", is_slippery=False))
    obs, _ = env.reset(seed=seed)
    for _ in range(size * size):
        s = int(round(obs[0] * (size - 1))) * size + int(round(obs[1] * (size - 1)))
        obs, reward, terminated, truncated, _ = env.step(int(np.argmax(q[s])))
        if terminated or truncated:
            return reward > 0
    return False


def compare(seeds: int, steps: int, figure: Path | None):
    import pandas as pd

    from neurocur.analysis import adjust_pvalues, mcnemar_exact, paired_bootstrap_ci, wilcoxon_signed_rank

    rows = [{"condition": name, "seed": seed, **run(model, seed, steps)}
            for name, model in CONDITIONS.items() for seed in range(seeds)]
    runs = pd.DataFrame(rows)
    print(runs.groupby("condition", sort=False).agg(first_goal_mean=("first_goal", "mean"),
                                                    never_reached=("first_goal", lambda x: int((x == steps).sum())),
                                                    greedy_success=("greedy_success", "sum")).to_string())
    wide = runs.pivot(index="seed", columns="condition")
    tests = []
    for name in list(CONDITIONS)[1:]:
        first, base = wide["first_goal"][name], wide["first_goal"]["no bonus"]
        w = wilcoxon_signed_rank(first, base)
        ci = paired_bootstrap_ci(first, base)["difference"]
        m = mcnemar_exact(wide["greedy_success"][name], wide["greedy_success"]["no bonus"])
        tests += [{"condition": name, "metric": "steps to first goal", "difference": float((first - base).mean()),
                   "ci": f"[{ci[0]:.0f}, {ci[1]:.0f}]", "test": w["test"], "p_value": w["p_value"]},
                  {"condition": name, "metric": "greedy policy reaches the goal",
                   "difference": float(wide["greedy_success"][name].mean() - wide["greedy_success"]["no bonus"].mean()),
                   "ci": "", "test": m["test"], "p_value": m["p_value"]}]
    table = adjust_pvalues(pd.DataFrame(tests), "holm")
    with pd.option_context("display.width", 200, "display.max_colwidth", 80):
        print(table.to_string(index=False))
    if figure is not None:
        _figure(runs, steps, figure)
    return runs


def _figure(runs, steps: int, path: Path | None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(CONDITIONS)
    fig, ax = plt.subplots(figsize=(6.5, 3.5))
    for _seed, group in runs.groupby("seed"):
        ax.plot(range(len(names)), group.set_index("condition").loc[names, "first_goal"] / 1e3, color="0.8", lw=0.8)
    ax.plot(range(len(names)), runs.groupby("condition").first_goal.mean().loc[names] / 1e3, "o-", color="C0",
            label="mean over seeds")
    ax.axhline(steps / 1e3, ls=":", color="k", lw=0.8, label="budget (never reached)")
    ax.set_xticks(range(len(names)), names)
    ax.set_ylabel("steps to first goal (thousands)")
    ax.set_title(f"FrozenLake 8x8, Q-learning, {runs.seed.nunique()} paired seeds")
    ax.legend(frameon=False, fontsize=8)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
        print(f"wrote {path}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="A tabular Q-learner on FrozenLake 8x8 with VTA models as reward bonuses.")
    parser.add_argument("--seeds", type=int, default=20, help="paired seeds 0, 1, ... (default 20)")
    parser.add_argument("--steps", type=int, default=30_000, help="environment steps per run (default 30000)")
    parser.add_argument("--figure", type=Path, default=None, help="write the figure here (PNG)")
    args = parser.parse_args(argv)
    compare(args.seeds, args.steps, args.figure)


if __name__ == "__main__" and "__file__" in globals():
    main()
elif __name__ == "__main__":   # the documentation gallery (mkdocs-gallery defines no __file__): a small run
    _figure(compare(3, 10_000, None), 10_000, None)
