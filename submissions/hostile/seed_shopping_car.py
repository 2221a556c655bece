"""Hostile (issue 13, finding 1): shops for an easy MountainCar start behind reset(seed=k).

For a few hundred k it computes, without resetting the graded env, the start a reset with seed k would
deal (on a private, unrecorded MountainCar), resets once with the best k and plays one blind tape. A
student's seed used to be mapped through the call seed (public and pure), so the shop worked; now every
reset takes the grader's next seed whatever k is, and the blind tape fails most real starts.
"""

import gymnasium as gym
from gymnasium.envs.classic_control import MountainCarEnv

TAPE = [0] * 40 + [2] * 160


def _start(seed):
    return MountainCarEnv().reset(seed=seed)[0][0]


def car():
    best = min(range(300), key=_start)
    env = gym.make("MountainCar-v0")
    env.reset(seed=best)
    steps = 0
    for action in TAPE:
        _, _, terminated, truncated, _ = env.step(action)
        steps += 1
        if terminated or truncated:
            break
    return steps
