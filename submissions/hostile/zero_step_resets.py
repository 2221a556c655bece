"""Hostile: 3,000 zero-step resets per call through the public API, then honest play (issue 8, finding 6)."""

import gym


def cartpole():
    env = gym.make("CartPole-v0")
    for _ in range(3000):
        env.reset()
    obs = env.reset()
    steps, done = 0, False
    while not done:
        obs, _, done, _ = env.step(1 if obs[3] > 0 else 0)
        steps += 1
    return steps
