# opengym.py
"""Volume 2: OpenGym AI.
Priya Natarajan
Math 321
"""

import gym
import numpy as np


def cartpole():
    """Average number of steps the pole stays up over 100 runs."""
    env = gym.make("CartPole-v0")
    lengths = []
    for episode in range(100):
        obs = env.reset()
        done = False
        t = 0
        while not done:
            obs, reward, done, info = env.step(int(obs[3] > 0))
            t += 1
        lengths.append(t)
    env.close()
    return np.mean(lengths)


def random_blackjack(n):
    """Random actions for n games; returns the share of wins."""
    env = gym.make("Blackjack-v0")
    wins = 0
    for game in range(n):
        done = False
        while not done:
            env.reset()
            obs, reward, done, _ = env.step(env.action_space.sample())
        wins += reward > 0
    return wins / n
