# gymnasium.py
"""compare() in a module that never trains the tables it reads (edition 4, problem 7).

The notebook's training cells were left out of this .py: nothing at the top level or under
`if __name__ == "__main__":` calls qlearn or sarsa0, so when the file runs as a script compare() finds no
`q_table_decay`: failed, the feedback saying where a .py trains them.
"""

import gymnasium as gym
import numpy as np


def compare():
    """Mean total reward of 1 000 greedy Taxi-v3 episodes with the Q-learning and the SARSA tables."""
    env = gym.make("Taxi-v3")
    means = []
    for table in (q_table_decay, sarsa_table_decay):  # noqa: F821 (never trained in this file)
        totals = []
        for _ in range(1000):
            state, info = env.reset()
            total, done = 0, False
            while not done:
                state, reward, terminated, truncated, info = env.step(np.argmax(table[state]))
                total += reward
                done = terminated or truncated
            totals.append(total)
        means.append(np.mean(totals))
    return means[0], means[1]
