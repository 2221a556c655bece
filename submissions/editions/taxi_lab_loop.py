# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 6 only). Honest: the lab loop, on terminated only, with a helper per table."""
import gymnasium as gym
import numpy as np


def play(table, env):
    rewards = []
    for _ in range(1000):
        state, info = env.reset()
        total, done = 0, False
        while not done:
            state, reward, done, truncated, info = env.step(np.argmax(table[state]))
            total += reward
        rewards.append(total)
    return np.mean(rewards)


def taxi(q_table, q_table_decay):
    env = gym.make("Taxi-v3")
    return play(q_table, env), play(q_table_decay, env)
