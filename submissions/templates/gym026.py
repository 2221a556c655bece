# opengym.py (the notebook opengym.ipynb as a script)
"""OpenGym AI, gym 0.26.
<Name>
<Class>
<Date>

Edition 2 of the lab, written for gymgrade from the edition's description: gym 0.26's API
(reset returns (observation, info), step returns five values); find_qvalues is provided, every problem
is still to be written.
"""

import random

import gym
import gym_toytext  # noqa: F401  (the toy-text games gym 0.26 no longer registers)
import numpy as np
from IPython.display import clear_output


def find_qvalues(env, alpha=.1, gamma=.6, epsilon=.1):
    """Train a Q-table with Q-learning (provided).

    Parameters:
        env (str): the environment's name
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): exploration rate

    Returns:
        (ndarray): the Q-table, one row per state
    """
    env = gym.make(env)
    q_table = np.zeros((env.observation_space.n, env.action_space.n))
    for i in range(1, 100_001):
        state, info = env.reset()
        done = False
        while not done:
            if random.uniform(0, 1) < epsilon:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])
            next_state, reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            best_next = np.max(q_table[next_state])
            q_table[state, action] = (1 - alpha) * q_table[state, action] + alpha * (reward + gamma * best_next)
            state = next_state
        if i % 100 == 0:
            clear_output(wait=True)
            print(f"Episode: {i}")
    env.close()
    return q_table


# Problem 1
def random_blackjack(n):
    """Play n games of Blackjack with random actions.

    Parameters:
        n (int): the number of games to play

    Returns:
        (float): the fraction of the games won
    """
    raise NotImplementedError("Problem 1 incomplete")


# Problem 2
def blackjack(n=11):
    """Play 10 000 games of Blackjack, drawing while the hand is at most n.

    Parameters:
        n (int): the largest hand the player still draws on

    Returns:
        (float): the fraction of the games won
    """
    raise NotImplementedError("Problem 2 incomplete")


# Problem 3
def cartpole():
    """Keep the pole of CartPole-v1 up using the velocity of its tip.

    Returns:
        (int): the number of steps the episode lasted
    """
    raise NotImplementedError("Problem 3 incomplete")


# Problem 4
def car():
    """Drive MountainCar-v0 up to the flag.

    Returns:
        (int): the number of steps it took
    """
    raise NotImplementedError("Problem 4 incomplete")


# Problem 5
def taxi(q_table):
    """Compare random play with the Q-table's greedy play in Taxi-v3 over 10 000 runs each.

    Parameters:
        q_table (ndarray): the table find_qvalues trained

    Returns:
        (float): the mean total reward of random play
        (float): the mean total reward of the Q-table's play
    """
    raise NotImplementedError("Problem 5 incomplete")
