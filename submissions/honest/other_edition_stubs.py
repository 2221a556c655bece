# opengym.py
"""Volume 2: OpenGym AI.
<Name>
<Class>
<Date>
"""

import gymnasium as gym
import numpy as np


def random_blackjack(n):
    """Play n games with random actions; return the fraction won."""
    env = gym.make("Blackjack-v1", natural=False, sab=False)
    wins = 0
    for _ in range(n):
        obs, info = env.reset()
        terminated = truncated = False
        while not (terminated or truncated):
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        wins += reward > 0
    env.close()
    return wins / n


def car(render=False):
    """
    Solve the MountainCar problem.

    Returns:
        iterations (int): number of steps to reach the flag
    """
    pass


def taxi(q_table, q_table_decay):
    """
    Compare naive and q-learning algorithms.

    Parameters:
        q_table (ndarray nxm): table from find_qvalues
        q_table_decay (ndarray nxm): table from find_qvalues with a decaying epsilon

    Returns:
        Average reward of naive algorithm (float)
        Average reward of q-learning (float)
        Average reward of q-learning with decay (float)
    """
    raise NotImplementedError("Problem 5 Incomplete")
