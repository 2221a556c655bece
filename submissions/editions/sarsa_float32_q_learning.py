# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problems 5 and 7). Q-learning on a float32 table: the looser
float32 tolerance must still catch the mistake and name it."""
import gymnasium as gym
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    q = np.zeros((500, 6), dtype=np.float32)
    for i in range(1, N + 1):
        eps = epsilon_decay(i, N) if decay else epsilon
        s, _ = env.reset()
        a = env.action_space.sample() if np.random.rand() < eps else int(np.argmax(q[s]))
        done = False
        while not done:
            s2, r, done, _, _ = env.step(a)
            a2 = env.action_space.sample() if np.random.rand() < eps else int(np.argmax(q[s2]))
            q[s, a] += alpha * (r + gamma * np.max(q[s2]) - q[s, a])
            s, a = s2, a2
    return q
