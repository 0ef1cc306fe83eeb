"""Train PPO (Stable-Baselines3) on urdfkit/SimpleDriving-v0 for a few CPU minutes.

Not run in CI (torch is heavy):

    pip install "urdfkit[gym]" stable-baselines3
    python examples/gym_ppo.py --steps 200000

It prints the success rate of the trained policy over 50 evaluation episodes.
"""

import argparse

import gymnasium as gym
import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

import urdfkit.gym  # noqa: F401

ap = argparse.ArgumentParser()
ap.add_argument("--steps", type=int, default=200_000)
a = ap.parse_args()
envs = make_vec_env("urdfkit/SimpleDriving-v0", n_envs=4, seed=0)
model = PPO("MlpPolicy", envs, n_steps=512, batch_size=256, gamma=0.98, verbose=1, seed=0)
model.learn(total_timesteps=a.steps)
env = gym.make("urdfkit/SimpleDriving-v0")
wins, returns = 0, []
for k in range(50):
    obs, _ = env.reset(seed=1000 + k)
    done, total = False, 0.0
    while not done:
        action, _ = model.predict(obs, deterministic=True)
        obs, reward, terminated, truncated, info = env.step(action)
        total += reward
        done = terminated or truncated
    wins += bool(info.get("is_success"))
    returns.append(total)
print(f"after {a.steps} steps: goals reached in {wins}/50 episodes, mean return "
      f"{np.mean(returns):.1f}")
