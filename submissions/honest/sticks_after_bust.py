# opengym.py
"""Volume 2: OpenGym AI.
Sam Ortiz
Math 321
"""

import gym
import numpy as np


def random_blackjack(n):
    """Random blackjack: hit while a coin says so, then stand."""
    env = gym.make('Blackjack-v0')
    wins = 0
    for _ in range(n):
        env.reset()
        while env.action_space.sample():
            env.step(1)
        observation, reward, done, info = env.step(0)
        if reward == 1:
            wins += 1
    return wins / n


def blackjack(n=11):
    """Draw while my hand is at most n, then stand. Returns the win percentage over 10000 games."""
    env = gym.make('Blackjack-v0')
    won = 0
    for _ in range(10000):
        current_hand = env.reset()[0]
        while current_hand <= n:
            observation, reward, done, info = env.step(1)
            current_hand = observation[0]
        observation, reward, done, info = env.step(0)
        won += reward == 1
    return 100 * won / 10000
