# opengym.py
"""Volume 2: OpenGym AI.
Sam Yoder
Math 347
Oct 4

The lab's template as handed out: find_qvalues is provided, every problem is still to be written.
"""

import gym
import numpy as np
from IPython.display import clear_output
import random


def find_qvalues(env, alpha=.1, gamma=.6, epsilon=.1):
    """
    Use the Q-learning algorithm to find qvalues.

    Parameters:
        env (str): environment name
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): maximum value

    Returns:
        q_table (ndarray nxm)
    """
    # Make environment
    env = gym.make(env)
    # Make Q-table
    q_table = np.zeros((env.observation_space.n, env.action_space.n))

    # Train
    for i in range(1, 100001):
        # Reset state
        state = env.reset()

        epochs, penalties, reward, = 0, 0, 0
        done = False

        while not done:
            # Accept based on alpha
            if random.uniform(0, 1) < epsilon:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])

            # Take action
            next_state, reward, done, info = env.step(action)

            # Calculate new qvalue
            old_value = q_table[state, action]
            next_max = np.max(q_table[next_state])

            new_value = (1 - alpha) * old_value + alpha * (reward + gamma * next_max)
            q_table[state, action] = new_value

            # Check if penalty is made
            if reward == -10:
                penalties += 1

            # Get next observation
            state = next_state
            epochs += 1

        # Print episode number
        if i % 100 == 0:
            clear_output(wait=True)
            print(f"Episode: {i}")

    print("Training finished.")
    return q_table


# Problem 1
def random_blackjack(n):
    """Play n games of Blackjack with random actions.

    Parameters:
        n (int): how many games to play

    Returns:
        (float): the share of the n games that the player won
    """
    raise NotImplementedError("Problem 1 Incomplete")


# Problem 2
def blackjack(n=11):
    """Play 10000 games of Blackjack, drawing while the hand is at most n.

    Parameters:
        n (int): the largest hand on which the player still draws

    Returns:
        (float): the share of the 10000 games that the player won
    """
    raise NotImplementedError("Problem 2 Incomplete")


# Problem 3
def cartpole():
    """Balance the pole: push toward the side the tip is falling to."""
    env = gym.make("CartPole-v0")
    obs = env.reset()
    done = False
    steps = 0
    while not done:
        action = 1 if obs[3] > 0 else 0
        obs, reward, done, info = env.step(action)
        steps += 1
    env.close()
    return steps


# Problem 4
def car():
    """Drive the car in MountainCar-v0 up to the flag.

    Returns:
        (int): the number of steps it took
    """
    raise NotImplementedError("Problem 4 Incomplete")


# Problem 5
def taxi(q_table):
    """Compare random actions with the actions of a Q-table in Taxi-v3.

    Parameters:
        q_table (ndarray): the Q-table from find_qvalues

    Returns:
        (float): mean total reward of 10000 random episodes
        (float): mean total reward of 10000 episodes following the Q-table
    """
    raise NotImplementedError("Problem 5 Incomplete")
