"""
# PPO with a curiosity bonus

stable-baselines3's PPO with a neurocur VTA model as its curiosity bonus (needs ``neurocur[rl]``).

    pip install "neurocur[rl]"
    PYTHONPATH=. python examples/rl_ppo.py [--model vta.novelty] [--env MountainCar-v0] [--steps 20000] [--scale 0.1] [--threads 1]

Each of PPO's environments is wrapped in [`neurocur.rl.IntrinsicReward`][neurocur.rl.wrappers.IntrinsicReward] (each with its own
memory; stable-baselines3 vectorises single environments itself), PPO learns on the wrapped
reward, and the learned policy is then run deterministically on the bare environment for 10
episodes, whose mean return (the environment's reward alone) is printed. A demonstration of the
wiring, not a study: one seed, a short budget.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np


def main(argv=None) -> None:
    from neurocur.config import extra
    from neurocur.rl import IntrinsicReward

    with extra("rl", "examples/rl_ppo.py"):
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.env_util import make_vec_env

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

    def make():
        env = gym.make(args.env)
        return env if args.model == "none" else IntrinsicReward(env, args.model, scale=args.scale)

    venv = make_vec_env(make, n_envs=args.envs, seed=args.seed)
    agent = PPO("MlpPolicy", venv, seed=args.seed, verbose=0).learn(total_timesteps=args.steps)
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


if __name__ == "__main__":
    main()
