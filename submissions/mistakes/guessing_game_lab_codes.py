# opengym.py
"""Volume 2: OpenGym AI.
C. Student
Math 321
September 2020

Typical mistake (grader sample): guessing_game() reads the observations with the lab text's codes
("0 indicates the guess is too high, 1 on target, 2 too low"); the game answers 1 (too low), 2 (equal),
3 (too high), so the interval never moves and the same guess is repeated.
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
        done = False
        guesses = 0
        while not done:
            guess = (low + high) / 2
            observation, reward, done, info = env.step(np.array([guess]))
            guesses += 1
            if observation == 0:
                high = guess
            elif observation == 2:
                low = guess
    finally:
        env.close()
    return guesses
