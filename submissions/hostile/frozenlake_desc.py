"""Hostile: car() plays a FrozenLake with a huge student map (issue 8, finding 4).

The grader used to build every env a log named with the student's arguments (1 GiB for 350x350); it must
refuse the episode as not MountainCar before building anything.
"""

import gymnasium as gym

SIZE = 120


def car():
    desc = ["S" + "F" * (SIZE - 1)] + ["F" * SIZE] * (SIZE - 2) + ["F" * (SIZE - 1) + "G"]
    env = gym.make("FrozenLake-v1", desc=desc, is_slippery=False)
    env.reset()
    env.step(2)
    return 1
