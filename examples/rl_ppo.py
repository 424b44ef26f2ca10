"""
# PPO with a curiosity bonus

stable-baselines3's PPO with a neurocur VTA model as its curiosity bonus (needs ``neurocur[rl]``).

    pip install "neurocur[rl]"
    PYTHONPATH=. python examples/rl_ppo.py [--model vta.novelty] [--env MountainCar-v0] [--steps 20000] [--scale 0.1] [--threads 1]

Each of PPO's environments is wrapped in `neurocur.rl.IntrinsicReward` (each with its own
memory; stable-baselines3 vectorises single environments itself), PPO learns on the wrapped
reward, and the learned policy is then run deterministically on the bare environment for 10
episodes, whose mean return (the environment's reward alone) is printed. A demonstration of the
wiring, not a study: one seed, a short budget.

The documentation gallery trains one PPO agent on MountainCar-v0 with count novelty
(``vta.novelty``) for 8192 steps, the least PPO's defaults update on with 4 environments. Its
figure shows the bonus PPO was paid per step (each environment's wrapper reports it in
``info["intrinsic_reward"]``), averaged over blocks of 256 steps: it falls as the car's states
become familiar, while the environment pays -1 per step throughout (the car never reaches the flag).
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np


class Bonuses(gym.Wrapper):
    """Records each step's intrinsic and extrinsic reward (``info`` of :class:`neurocur.rl.IntrinsicReward`)."""

    def __init__(self, env, log: list):
        super().__init__(env)
        self.log = log

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.log.append((info.get("intrinsic_reward", 0.0), info.get("extrinsic_reward", reward)))
        return obs, reward, terminated, truncated, info


def train(env_id: str, model: str, steps: int, *, scale: float, envs: int, seed: int):
    """PPO trained ``steps`` steps on ``envs`` copies of ``env_id``, each wrapped in
    :class:`neurocur.rl.IntrinsicReward` with the VTA ``model`` (``"none"``: no bonus); returns
    the agent and the (intrinsic, extrinsic) reward of every step, in the order they were taken."""
    from neurocur.config import extra
    from neurocur.rl import IntrinsicReward

    with extra("rl", "examples/rl_ppo.py"):
        from stable_baselines3 import PPO
        from stable_baselines3.common.env_util import make_vec_env

    log: list = []

    def make():
        env = gym.make(env_id)
        return Bonuses(env if model == "none" else IntrinsicReward(env, model, scale=scale), log)

    venv = make_vec_env(make, n_envs=envs, seed=seed)
    return PPO("MlpPolicy", venv, seed=seed, verbose=0).learn(total_timesteps=steps), np.array(log)


def figure(log: np.ndarray, block: int = 256) -> None:
    """The bonus per step, averaged over blocks of ``block`` steps (the environment's reward in the title)."""
    import matplotlib.pyplot as plt

    n = len(log) // block * block
    means = log[:n].reshape(-1, block, 2).mean(axis=1)
    fig, ax = plt.subplots(figsize=(6.5, 3.2))
    ax.plot((np.arange(len(means)) + 0.5) * block, means[:, 0], "o-", color="C0")
    ax.set_xlabel("training step (all environments)")
    ax.set_ylabel("bonus per step (scale 0.1)")
    ax.set_title(f"PPO on MountainCar-v0: count novelty's bonus (vta.novelty)\n"
                 f"the environment paid {means[:, 1].mean():.2f} per step throughout", fontsize=10)
    fig.tight_layout()


def main(argv=None) -> None:
    from neurocur.config import extra

    with extra("rl", "examples/rl_ppo.py"):
        import torch

    parser = argparse.ArgumentParser(
        description="stable-baselines3's PPO with a neurocur VTA model as its curiosity bonus.")
    parser.add_argument("--model", default="vta.novelty", help="a VTA model, or 'none' for no bonus")
    parser.add_argument("--env", default="MountainCar-v0")
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--scale", type=float, default=0.1)
    parser.add_argument("--envs", type=int, default=4)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="torch's threads (default 1)")
    args = parser.parse_args(argv)
    torch.set_num_threads(args.threads)

    agent, _ = train(args.env, args.model, args.steps, scale=args.scale, envs=args.envs, seed=args.seed)
    env, returns = gym.make(args.env), []
    for episode in range(10):
        obs, _ = env.reset(seed=args.seed + 1000 + episode)
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, _ = env.step(agent.predict(obs, deterministic=True)[0])
            total, done = total + float(reward), terminated or truncated
        returns.append(total)
    print(f"{args.env}, PPO, {args.model} (scale {args.scale}), {args.steps} steps: "
          f"mean return of the greedy policy over 10 episodes {np.mean(returns):.1f}")


if __name__ == "__main__" and "__file__" in globals():
    main()
elif __name__ == "__main__":   # the documentation gallery (mkdocs-gallery defines no __file__): a small run
    import torch

    torch.set_num_threads(1)
    figure(train("MountainCar-v0", "vta.novelty", 8192, scale=0.1, envs=4, seed=0)[1])
