"""A random policy on urdfkit/SimpleDriving-v0: episodes, returns, successes.

    pip install "urdfkit[gym]"
    python examples/gym_random.py
"""

import gymnasium as gym
import numpy as np

import urdfkit.gym  # noqa: F401  (registers urdfkit/SimpleDriving-v0)

env = gym.make("urdfkit/SimpleDriving-v0")
returns, successes = [], 0
obs, info = env.reset(seed=0)
env.action_space.seed(0)
episode_return = 0.0
while len(returns) < 20:
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    episode_return += reward
    if terminated or truncated:
        returns.append(episode_return)
        successes += bool(info.get("is_success"))
        episode_return = 0.0
        obs, info = env.reset()
env.close()
print(f"20 episodes: mean return {np.mean(returns):.2f}, goals reached {successes}")
