# opengym.py
"""Volume 2: OpenGym AI.
C. Student
Math 321
September 2020

Typical mistake (grader sample): guessing_game() bisects but stops only when a guess is exactly the
target (observation 2), so it keeps guessing after the game was won (within 10 of the target).
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
        observation = 0
        guesses = 0
        while observation != 2:
            guess = (low + high) / 2
            observation, reward, done, info = env.step(np.array([guess]))
            guesses += 1
            if observation == 1:
                low = guess
            elif observation == 3:
                high = guess
    finally:
        env.close()
    return guesses
