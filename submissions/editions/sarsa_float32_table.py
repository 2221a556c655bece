# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problems 5 and 7). Honest SARSA(0) with a float32 table, as
students who copy `np.zeros(..., dtype=np.float32)` from a tutorial write it: every update rounds to
float32, and the table is returned as the array it is."""
import gymnasium as gym
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta


def choose(q_table, state, epsilon, env):
    if np.random.uniform(0, 1) < epsilon:
        return env.action_space.sample()
    return int(np.argmax(q_table[state]))


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    q_table = np.zeros((env.observation_space.n, env.action_space.n), dtype=np.float32)
    penalties = 0
    for i in range(1, N + 1):
        rate = epsilon_decay(i, N) if decay else epsilon
        state, _ = env.reset()
        action = choose(q_table, state, rate, env)
        done = False
        while not done:
            next_state, reward, done, _, _ = env.step(action)
            next_action = choose(q_table, next_state, rate, env)
            q_table[state, action] += alpha * (reward + gamma * q_table[next_state, next_action] - q_table[state, action])
            if reward == -10:
                penalties += 1
            state, action = next_state, next_action
    return q_table, penalties
