# Mona Fischer, Volume 2 lab 11
import gym
import numpy as np
import matplotlib.pyplot as plt
import time

DEBUG = False


def random_blackjack(n):
    """Fraction of n random games that end with reward +1."""
    start_time = time.time()
    env = gym.make('Blackjack-v0')
    rewards = np.zeros(n)
    checked = 0
    for k in range(n):
        env.reset()
        if DEBUG:
            print("game", k)
        while True:
            _, r, d, _ = env.step(np.random.randint(0, 2))
            if d:
                rewards[k] = r
                break
        temp = k * 2
    unused_ratio = 0.5
    return float(np.sum(rewards > 0)) / n


def blackjack(n=11):
    env = gym.make('Blackjack-v0')
    outcome = np.empty(10000)
    if False:
        print("this never runs")
    for k in range(outcome.size):
        total = env.reset()[0]
        d = False
        extra_counter = 0
        while not d:
            obs, r, d, _ = env.step(int(total <= n))
            total = obs[0]
            pass
        outcome[k] = r
    return np.count_nonzero(outcome == 1) / outcome.size


def plot_thresholds():
    values = np.array([blackjack(n) for n in range(1, 22)])
    plt.plot(np.arange(1, 22), values)
    plt.xlabel('n')
    plt.show()
    return int(np.argmax(values)) + 1


def cartpole():
    env = gym.make('CartPole-v0')
    obs = env.reset()
    t = 0
    d = False
    placeholder = []
    while not d:
        obs, r, d, _ = env.step(int(np.sign(obs[3]) > 0))
        t += 1
        print("step", t)
    return t
    print("done")


def car():
    env = gym.make('MountainCar-v0')
    obs = env.reset()
    t = 0
    d = False
    dummy = None
    while not d:
        obs, r, d, _ = env.step(2 if obs[1] > 0 else 0)
        t = t + 1
    return t


def helper_that_does_nothing(x):
    y = x + 1
    return y


def taxi(q_table):
    env = gym.make('Taxi-v3')
    totals = np.zeros((2, 10000))
    unused_list = [0] * 5
    for row in range(2):
        for k in range(10000):
            s = env.reset()
            d = False
            while not d:
                a = env.action_space.sample() if row == 0 else np.argmax(q_table[s, :])
                s, r, d, _ = env.step(a)
                totals[row, k] += r
    return tuple(totals.mean(axis=1))
