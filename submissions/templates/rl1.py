# gymnasium.py (the notebook gymnasium.ipynb as a script)
"""Reinforcement Learning 1: Gymnasium.
<Name>
<Class>
<Date>

Edition 4 of the lab, written for gymgrade from the edition's description: qlearn is provided, every
problem (epsilon_decay, taxi with two tables, sarsa0, compare) is still to be written. As in the course's
notebook, the learners take the environment's name and make it themselves (`env = gym.make(env)`), and
compare() plays the tables the training code trains; in a .py file that code goes under
`if __name__ == "__main__":` (the end of this file), which the grader runs as a script before compare().
"""

import random

import gymnasium as gym
import numpy as np
from IPython import display


# Problem 1
def random_blackjack(n):
    """Play n episodes of Blackjack-v1 taking random actions until each ends.

    Parameters:
        n (int): the number of episodes to play

    Returns:
        (float): the fraction of the episodes won
    """
    raise NotImplementedError("Problem 1 incomplete")


# Problem 2
def blackjack(n=11):
    """Play 10 000 episodes of Blackjack-v1, drawing while the hand is at most n.

    Parameters:
        n (int): the largest hand the player still draws on

    Returns:
        (float): the fraction of the episodes won
    """
    raise NotImplementedError("Problem 2 incomplete")


# Problem 3
def cartpole(render=False):
    """Keep the pole of CartPole-v1 up, acting on the angular velocity of its tip.

    Parameters:
        render (bool): whether to draw the environment

    Returns:
        (int): the number of timesteps the episode lasted
    """
    raise NotImplementedError("Problem 3 incomplete")


# Problem 4
def car(render=False):
    """Drive MountainCar-v0 up to the flag.

    Parameters:
        render (bool): whether to draw the environment

    Returns:
        (int): the number of timesteps it took
    """
    raise NotImplementedError("Problem 4 incomplete")


# Problem 5
def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    """The exploration rate of an episode under a linear decay from epsilon_start towards epsilon_end.

    Parameters:
        episode (int): the episode, counted from 1
        N (int): the number of training episodes
        epsilon_start (float): the rate of the first episode
        epsilon_end (float): the rate the decay heads towards

    Returns:
        (float): the episode's epsilon
    """
    raise NotImplementedError("Problem 5 incomplete")


def qlearn(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    """Train a Q-table with Q-learning (provided).

    Parameters:
        env (str): the environment's name (a gym id such as "Taxi-v3")
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): exploration rate (the first one when decaying)
        N (int): the number of training episodes
        decay (bool): whether episode i explores with epsilon_decay(i, N)

    Returns:
        (ndarray): the Q-table, one row per state
        (int): the number of penalties (rewards of -10) taken while training
    """
    env = gym.make(env)
    q_table = np.zeros((env.observation_space.n, env.action_space.n))
    penalties = 0
    for i in range(1, N + 1):
        state, info = env.reset()
        rate = epsilon_decay(i, N) if decay else epsilon
        done = False
        while not done:
            if random.uniform(0, 1) < rate:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])
            next_state, reward, terminated, truncated, info = env.step(action)
            best_next = np.max(q_table[next_state])
            q_table[state, action] = (1 - alpha) * q_table[state, action] + alpha * (reward + gamma * best_next)
            if reward == -10:
                penalties += 1
            state = next_state
            done = terminated
        if i % 1000 == 0:
            display.clear_output(wait=True)
            print(f"Episode: {i}")
    env.close()
    return q_table, penalties


# Problem 6
def taxi(q_table, q_table_decay):
    """Play 1 000 greedy Taxi-v3 episodes with each table.

    Parameters:
        q_table (ndarray): a table trained with a constant epsilon
        q_table_decay (ndarray): a table trained with a decaying epsilon

    Returns:
        (float): the mean total reward with q_table
        (float): the mean total reward with q_table_decay
    """
    raise NotImplementedError("Problem 6 incomplete")


# Problem 7
def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    """Train a Q-table with SARSA(0).

    Parameters:
        env (str): the environment's name (a gym id such as "Taxi-v3")
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): exploration rate (the first one when decaying)
        N (int): the number of training episodes
        decay (bool): whether episode i explores with epsilon_decay(i, N)

    Returns:
        (ndarray): the Q-table
    """
    raise NotImplementedError("Problem 7 incomplete")


def compare():
    """Play 1 000 greedy Taxi-v3 episodes with the Q-learning and the SARSA tables trained above.

    Returns:
        (float): the mean total reward with the Q-learning table
        (float): the mean total reward with the SARSA table
    """
    raise NotImplementedError("Problem 7 incomplete")


if __name__ == "__main__":
    # The notebook's training cells: the tables compare() plays.
    q_table, _ = qlearn("Taxi-v3")
    q_table_decay, _ = qlearn("Taxi-v3", decay=True)
    sarsa_table_decay = sarsa0("Taxi-v3", decay=True)
    print(compare())
