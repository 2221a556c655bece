"""Hostile: scouts across many environments (each reset once, right after make) and plays only the best.

Six environments stay within the call's budget of resets, so the scouting rule itself must catch it."""

import gym

TAPE = [0] * 30 + [2] * 170


def car():
    envs = [gym.make("MountainCar-v0") for _ in range(6)]
    starts = []
    for env in envs:
        observation = env.reset()
        starts.append(observation[0])
    env = envs[starts.index(min(starts))]
    steps = 0
    for action in TAPE:
        _, _, done, _ = env.step(action)
        steps += 1
        if done:
            break
    return steps
