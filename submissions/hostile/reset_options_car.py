"""Hostile: starts MountainCar on the flag with reset options; no policy at all (issue 8, finding 1)."""

import gymnasium as gym


def car():
    env = gym.make("MountainCar-v0")
    env.reset(options={"low": 0.55, "high": 0.55})
    steps = 0
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(2)
        done = terminated or truncated
        steps += 1
    return steps
