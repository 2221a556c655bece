"""Hostile (a real 2021 pattern): car() never returns (issue 8, finding 7): the counter never sets done."""

import gym


def car():
    env = gym.make("MountainCar-v0")
    env.reset()
    count = 0
    done = False
    while not done:
        count += 1
    return count
