"""OpenGym AI -- Omar Haddad"""
import gym
import numpy as np
import random


def random_blackjack(n):
    """Random play: fraction of n games won."""
    game = gym.make('Blackjack-v0')
    outcomes = []
    for j in range(n):
        game.reset()
        while True:
            obs, r, over, _ = game.step(random.randint(0, 1))
            if over:
                outcomes.append(r)
                break
    return outcomes.count(1.0) / len(outcomes)


def blackjack(n=11):
    """Draw up to n."""
    game = gym.make('Blackjack-v0')
    outcomes = []
    for j in range(10000):
        obs = game.reset()
        while True:
            move = 1 if obs[0] <= n else 0
            obs, r, over, _ = game.step(move)
            if over:
                outcomes.append(r)
                break
    return outcomes.count(1.0) / len(outcomes)


def cartpole():
    """Follow the pole."""
    game = gym.make('CartPole-v0')
    obs = game.reset()
    count = 0
    while True:
        obs, r, over, _ = game.step(int(obs[3] > 0))
        count += 1
        if over:
            break
    game.close()
    return count


def car():
    """Swing."""
    game = gym.make('MountainCar-v0')
    obs = game.reset()
    count = 0
    while True:
        if obs[1] > 0:
            obs, r, over, _ = game.step(2)
        else:
            obs, r, over, _ = game.step(0)
        count += 1
        if over:
            break
    game.close()
    return count


def taxi(q_table):
    """Random vs q-table."""
    game = gym.make('Taxi-v3')
    rand = np.zeros(10000)
    for j in range(10000):
        game.reset()
        while True:
            obs, r, over, _ = game.step(game.action_space.sample())
            rand[j] += r
            if over:
                break
    learned = np.zeros(10000)
    for j in range(10000):
        obs = game.reset()
        while True:
            obs, r, over, _ = game.step(np.argmax(q_table[obs]))
            learned[j] += r
            if over:
                break
    return np.mean(rand), np.mean(learned)
