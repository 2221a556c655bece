"""gym 0.26 code whose Taxi loops wait for `terminated` only: the 200-step time limit is ignored.

Random episodes then run until the passenger happens to be delivered (thousands of steps). The sample plays
100 episodes per scenario instead of the lab's 10000 so that grading it stays quick; the diagnosis is the same.
"""

import gym
import numpy as np

EPISODES = 100


def taxi(q_table):
    env = gym.make("Taxi-v3")
    naive = []
    for _ in range(EPISODES):
        state, info = env.reset()
        terminated = False
        total = 0
        while not terminated:
            state, reward, terminated, truncated, info = env.step(env.action_space.sample())
            total += reward
        naive.append(total)
    learned = []
    for _ in range(EPISODES):
        state, info = env.reset()
        terminated = False
        total = 0
        while not terminated:
            state, reward, terminated, truncated, info = env.step(np.argmax(q_table[state]))
            total += reward
        learned.append(total)
    return np.mean(naive), np.mean(learned)
