"""Hostile: resets MountainCar without stepping until the start looks easy, then plays a blind tape.

Issue 8, finding 2: the zero-step resets used to be dropped before any check saw them.
"""

import gym

TAPE = [0] * 30 + [2] * 170


def car():
    env = gym.make("MountainCar-v0")
    observation = env.reset()
    while observation[0] > -0.5:
        observation = env.reset()
    steps = 0
    for action in TAPE:
        _, _, done, _ = env.step(action)
        steps += 1
        if done:
            break
    return steps
