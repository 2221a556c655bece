# opengym.py
"""Volume 2: OpenGym AI.
Jonas Berg
Math 321
10/5/2020
"""

import gym
import numpy as np
from IPython.display import clear_output
import random


def random_blackjack(n):
    """Play n games of blackjack at random and return the fraction won."""
    environment = gym.make("Blackjack-v0")
    victories = 0
    for g in range(n):
        environment.reset()
        finished = False
        while not finished:
            obs, payoff, finished, extra = environment.step(environment.action_space.sample())
        if payoff > 0:
            victories += 1
        if g == 500:
            print(victories / 500)
    environment.close()
    return victories / n


def blackjack(n=11):
    """Hit while the hand is at most n; return the fraction of 10000 games won."""
    environment = gym.make("Blackjack-v0")
    victories = 0
    for g in range(10000):
        player_sum, shown, soft = environment.reset()
        finished = False
        while not finished:
            if player_sum <= n:
                (player_sum, shown, soft), payoff, finished, extra = environment.step(1)
            else:
                (player_sum, shown, soft), payoff, finished, extra = environment.step(0)
        if payoff == 1:
            victories += 1
    environment.close()
    return victories / 10000


def cartpole():
    """Push the cart toward the side the pole tip is moving to."""
    environment = gym.make("CartPole-v0")
    obs = environment.reset()
    count = 0
    finished = False
    while not finished:
        move = 1 if obs[3] > 0 else 0
        obs, payoff, finished, extra = environment.step(move)
        count += 1
    environment.close()
    return count


def car():
    """Accelerate in the direction the car is already moving."""
    environment = gym.make("MountainCar-v0")
    pos, vel = environment.reset()
    count = 0
    finished = False
    while not finished:
        if vel < 0:
            move = 0
        else:
            move = 2
        (pos, vel), payoff, finished, extra = environment.step(move)
        count += 1
    environment.close()
    return count


def taxi(q_table):
    """Average reward of random play and of the q-table over 10000 episodes each."""
    environment = gym.make("Taxi-v3")
    rand_sum = 0
    for ep in range(10000):
        environment.reset()
        finished = False
        while not finished:
            s, payoff, finished, extra = environment.step(environment.action_space.sample())
            rand_sum += payoff
    greedy_sum = 0
    for ep in range(10000):
        s = environment.reset()
        finished = False
        while not finished:
            s, payoff, finished, extra = environment.step(np.argmax(q_table[s]))
            greedy_sum += payoff
    environment.close()
    return rand_sum / 10000, greedy_sum / 10000
