# opengym.py
"""Volume 2: OpenGym AI.
Alex Kim
"""

import gym
import numpy as np


def random_blackjack(n):
    env = gym.make("Blackjack-v0")
    results = np.zeros(n, dtype=np.float32)
    for i in range(n):
        env.reset()
        done = False
        while not done:
            _, r, done, _ = env.step(env.action_space.sample())
        results[i] = r
    return np.float32(np.sum(results == 1) / n)


def cartpole():
    env = gym.make("CartPole-v0")
    state = env.reset()
    count = 0.0
    done = False
    while not done:
        state, _, done, _ = env.step(1 if state[3] > 0 else 0)
        count += 1.0
    return count


def car():
    env = gym.make("MountainCar-v0")
    state = env.reset()
    total = 0
    done = False
    while not done:
        state, r, done, _ = env.step(0 if state[1] < 0 else 2)
        total += r
    return np.float64(-total)
