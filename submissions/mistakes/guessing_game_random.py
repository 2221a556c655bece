# opengym.py
"""Volume 2: OpenGym AI.
C. Student
Math 321
September 2020

Typical mistake (grader sample): guessing_game() guesses at random (env.action_space.sample()) until it
happens to win, almost never within the 200 guesses the game allows.
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
        done = False
        guesses = 0
        while not done:
            observation, reward, done, info = env.step(env.action_space.sample())
            guesses += 1
    finally:
        env.close()
    return guesses
