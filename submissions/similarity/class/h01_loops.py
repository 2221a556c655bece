# opengym.py
"""Volume 2: OpenGym AI.
Ada Quill
Math 321
10/3/2020
"""

import gym
import numpy as np
from IPython.display import clear_output
import random


def random_blackjack(n):
    """Play n games of blackjack at random and return the fraction won."""
    env = gym.make("Blackjack-v0")
    wins = 0
    for game in range(n):
        env.reset()
        done = False
        while not done:
            observation, reward, done, info = env.step(env.action_space.sample())
        if reward > 0:
            wins += 1
        if game == 500:
            print(wins / 500)
    env.close()
    return wins / n


def blackjack(n=11):
    """Hit while the hand is at most n; return the fraction of 10000 games won."""
    env = gym.make("Blackjack-v0")
    wins = 0
    for game in range(10000):
        hand, dealer, ace = env.reset()
        done = False
        while not done:
            if hand <= n:
                (hand, dealer, ace), reward, done, info = env.step(1)
            else:
                (hand, dealer, ace), reward, done, info = env.step(0)
        if reward == 1:
            wins += 1
    env.close()
    return wins / 10000


def cartpole():
    """Push the cart toward the side the pole tip is moving to."""
    env = gym.make("CartPole-v0")
    observation = env.reset()
    steps = 0
    done = False
    while not done:
        action = 1 if observation[3] > 0 else 0
        observation, reward, done, info = env.step(action)
        steps += 1
    env.close()
    return steps


def car():
    """Accelerate in the direction the car is already moving."""
    env = gym.make("MountainCar-v0")
    position, velocity = env.reset()
    steps = 0
    done = False
    while not done:
        if velocity < 0:
            action = 0
        else:
            action = 2
        (position, velocity), reward, done, info = env.step(action)
        steps += 1
    env.close()
    return steps


def taxi(q_table):
    """Average reward of random play and of the q-table over 10000 episodes each."""
    env = gym.make("Taxi-v3")
    random_total = 0
    for episode in range(10000):
        env.reset()
        done = False
        while not done:
            state, reward, done, info = env.step(env.action_space.sample())
            random_total += reward
    table_total = 0
    for episode in range(10000):
        state = env.reset()
        done = False
        while not done:
            state, reward, done, info = env.step(np.argmax(q_table[state]))
            table_total += reward
    env.close()
    return random_total / 10000, table_total / 10000
