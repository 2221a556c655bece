# opengym.py
"""Volume 2: OpenGym AI.
C. Student
Math 321
September 2020

Typical mistake (grader sample): guessing_game() bisects correctly but counts only the guesses that
missed, so every count is one short of the guesses the game took.
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
        low, high = -1000, 1000
        guess = (low + high) / 2
        observation, reward, done, info = env.step(np.array([guess]))
        guesses = 0
        while not done:
            # count the miss, then narrow the interval
            guesses += 1
            if observation == 1:
                low = guess
            else:
                high = guess
            guess = (low + high) / 2
            observation, reward, done, info = env.step(np.array([guess]))
    finally:
        env.close()
    return guesses
