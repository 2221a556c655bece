"""Hostile: cartpole() plays 100,000 Acrobot steps with no time limit (issue 8, finding 4).

Before the env was checked against the problem, the grader replayed all of them (~70 s per few calls).
"""

import gymnasium as gym


def cartpole():
    env = gym.make("Acrobot-v1", max_episode_steps=1_000_000)
    env.reset()
    for _ in range(100_000):
        env.step(0)
    return 200
