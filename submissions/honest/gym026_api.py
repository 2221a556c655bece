# opengym.py
"""Volume 2: OpenGym AI (gym 0.26 edition).
Morgan Diaz
"""

import gym
import numpy as np


def random_blackjack(n):
    env = gym.make("Blackjack-v1", natural=False, sab=False)
    wins = 0
    for _ in range(n):
        obs, info = env.reset()
        terminated, truncated = False, False
        while not (terminated or truncated):
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if reward == 1:
            wins += 1
    env.close()
    return wins / n


def blackjack(n=11):
    env = gym.make("Blackjack-v1", natural=False, sab=False)
    wins = 0
    for _ in range(10000):
        (player, dealer, ace), info = env.reset()
        done = False
        while not done:
            action = 1 if player <= n else 0
            (player, dealer, ace), reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
        wins += int(reward == 1)
    env.close()
    return wins / 10000


def cartpole():
    env = gym.make("CartPole-v1")
    obs, info = env.reset()
    steps = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(int(obs[3] > 0))
        steps += 1
        if terminated or truncated:
            break
    env.close()
    return steps
