"""Hostile: every guess within 10 of the midpoint, leaning toward the target that `info` shows.

No single guess leaves the midpoint search, but each leans toward `info["number"]`, so the winning window
is hit sooner than the observations allow: only the exact test of the total number of guesses sees it.
"""

import gymnasium as gym
import numpy as np


def guessing_game():
    env = gym.make("GuessingGame-v0")
    env.reset()
    low, high, guesses, done, target = -1000.0, 1000.0, 0, False, None
    while not done:
        middle = (low + high) / 2
        lean = 0.0 if target is None else 9.99 * float(np.sign(target - middle))
        observation, _, terminated, truncated, info = env.step(np.array([middle + lean]))
        guesses, done, target = guesses + 1, terminated or truncated, info["number"]
        if observation == 1:
            low = middle + lean
        else:
            high = middle + lean
    return guesses
