# opengym.py
"""Volume 2: OpenGym AI.
C. Student
Math 321
September 2020

Typical mistake (grader sample): guessing_game() walks up from -1000 in steps of 20 (the width of the
winning window), a linear search that never uses the observations.
"""

import gym
import numpy as np


def guessing_game():
    """Find the target of GuessingGame-v0.

    Returns:
        (int): the number of guesses it took
    """
    env = gym.make("GuessingGame-v0")
    try:
        env.reset()
        guess = -1000
        done = False
        guesses = 0
        while not done:
            observation, reward, done, info = env.step(np.array([guess]))
            guesses += 1
            guess += 20
    finally:
        env.close()
    return guesses
