"""Hostile: pins every CartPole start with reset options and plays a blind tape (issue 8, finding 1)."""

import gym

TAPE = [(step // 2) % 2 for step in range(200)]


def cartpole():
    env = gym.make("CartPole-v0")
    env.reset(options={"low": 0, "high": 0})
    steps = 0
    for action in TAPE:
        _, _, done, _ = env.step(action)
        steps += 1
        if done:
            break
    return steps
