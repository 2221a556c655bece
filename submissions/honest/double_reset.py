# opengym.py
"""Volume 2: OpenGym AI.
Jordan Lee
Math 321
October 2021
"""

import gym
import numpy as np
from IPython.display import clear_output
import random


def random_blackjack(n):
    """Play n random games of blackjack and return the fraction won."""
    env = gym.make("Blackjack-v0")
    env.reset()
    wins = 0
    for i in range(n):
        env.reset()
        obs = env.reset()  # start the next hand
        done = False
        while not done:
            obs, reward, done, info = env.step(env.action_space.sample())
        if reward > 0:
            wins += 1
    return wins / n


def cartpole():
    """Balance the pole by pushing toward the pole's tip velocity; return the number of steps."""
    env = gym.make("CartPole-v0")
    env.reset()
    pos = env.reset()
    done = False
    steps = 0
    while not done:
        action = 1 if pos[3] > 0 else 0
        pos, reward, done, info = env.step(action)
        steps += 1
    env.close()
    return steps


def car():
    """Get the car up the hill by pushing with its velocity; return the number of steps."""
    env = gym.make("MountainCar-v0")
    env.reset()
    obs = env.reset()
    steps = 0
    while True:
        obs, reward, done, info = env.step(2 if obs[1] >= 0 else 0)
        steps += 1
        if done:
            break
    env.close()
    return steps
