# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problems 5 and 7). Honest SARSA(0) on a float32 table written in
the (1 - alpha) form, which rounds differently from the lab's `+=` form, and returned as nested lists."""
import random

import gymnasium as gym
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    Q = np.zeros([500, 6], np.float32)

    def pick(s, eps):
        return env.action_space.sample() if random.random() < eps else int(Q[s].argmax())

    for i in range(1, N + 1):
        eps = epsilon_decay(i, N) if decay else epsilon
        s, _ = env.reset()
        a = pick(s, eps)
        terminated = False
        while not terminated:
            s2, r, terminated, truncated, _ = env.step(a)
            a2 = pick(s2, eps)
            Q[s, a] = (1 - alpha) * Q[s, a] + alpha * (r + gamma * Q[s2, a2])
            s, a = s2, a2
    return Q.tolist()
