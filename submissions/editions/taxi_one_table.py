# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 6 only). Plays q_table twice (copy-paste slip)."""
import gymnasium as gym
import numpy as np


def taxi(q_table, q_table_decay):
    env = gym.make("Taxi-v3")
    means = []
    for table in (q_table, q_table):
        rewards = []
        for _ in range(1000):
            state, info = env.reset()
            total, done = 0, False
            while not done:
                state, reward, terminated, truncated, info = env.step(np.argmax(table[state]))
                total += reward
                done = terminated or truncated
            rewards.append(total)
        means.append(np.mean(rewards))
    return means[0], means[1]
