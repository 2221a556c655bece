"""Hostile: scouts across many environments (each reset once, right after make) and plays only the best."""

import gym

TAPE = [0] * 30 + [2] * 170


def car():
    envs = [gym.make("MountainCar-v0") for _ in range(40)]
    starts = [env.reset()[0] for env in envs]
    env = envs[starts.index(min(starts))]
    steps = 0
    for action in TAPE:
        _, _, done, _ = env.step(action)
        steps += 1
        if done:
            break
    return steps
