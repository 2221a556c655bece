# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problems 5 and 7), sarsa0 written from the course's template
(`env (str)`, `env = gym.make(env)`), with a typical mistake: the update reads Q[s', a] of the action just
taken, and the next action is chosen only after it."""
import random

import gymnasium as gym
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    env = gym.make(env)
    q_table = np.zeros((env.observation_space.n, env.action_space.n))
    for i in range(1, N + 1):
        rate = epsilon_decay(i, N) if decay else epsilon
        state, info = env.reset()
        action = env.action_space.sample() if random.uniform(0, 1) < rate else np.argmax(q_table[state])
        done = False
        while not done:
            next_state, reward, done, truncated, info = env.step(action)
            old = q_table[state, action]
            q_table[state, action] = old + alpha * (reward + gamma * q_table[next_state, action] - old)
            state = next_state
            action = env.action_space.sample() if random.uniform(0, 1) < rate else np.argmax(q_table[state])
    env.close()
    return q_table
