# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problems 5 and 7). Honest SARSA(0) in another style: ties broken
at random, the loop stops on terminated or truncated, the (1 - alpha) form of the update, only the table
returned (as the template's docstring says)."""
import random

import gymnasium as gym
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta


def policy(Q, s, eps, env):
    if random.random() < eps:
        return env.action_space.sample()
    row = Q[s]
    return int(np.random.choice(np.flatnonzero(row == row.max())))


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    Q = np.zeros([env.observation_space.n, env.action_space.n])
    for i in range(1, N + 1):
        eps = epsilon_decay(i, N) if decay else epsilon
        s, _ = env.reset()
        a = policy(Q, s, eps, env)
        terminated = truncated = False
        while not (terminated or truncated):
            s2, r, terminated, truncated, _ = env.step(a)
            a2 = policy(Q, s2, eps, env)
            Q[s, a] = (1 - alpha) * Q[s, a] + alpha * (r + gamma * Q[s2, a2])
            s, a = s2, a2
    env.close()
    return Q
