"""Volume 2: OpenGym AI.
C. Student
Math 321
October 2022

Written for gym 0.24, the version between the two editions of the lab: the classic API (`obs = env.reset()`,
four-value `env.step`) with the ids gym then had (`Blackjack-v1`, whose registered rules are Sutton and
Barto's `sab=True`, and `CartPole-v1`).
"""

import gym


def random_blackjack(n):
    env = gym.make("Blackjack-v1")
    wins = 0
    for _ in range(n):
        env.reset()
        done = False
        while not done:
            state, reward, done, info = env.step(env.action_space.sample())
        wins += reward == 1
    return wins / n


def blackjack(n=11):
    env = gym.make("Blackjack-v1")
    wins = 0
    for _ in range(10000):
        state = env.reset()
        done = False
        while not done:
            state, reward, done, info = env.step(int(state[0] <= n))
        wins += reward == 1
    return wins / 10000


def cartpole():
    env = gym.make("CartPole-v1")
    state = env.reset()
    done = False
    steps = 0
    while not done:
        state, reward, done, info = env.step(int(state[3] > 0))
        steps += 1
    return steps
