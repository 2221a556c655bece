# Solutions to the OpenGym AI lab (posted 2021)
import gym
import numpy as np
import random


def random_blackjack(n):
    env = gym.make('Blackjack-v0')
    results = []
    for i in range(n):
        env.reset()
        while True:
            state, reward, done, info = env.step(random.randint(0, 1))
            if done:
                results.append(reward)
                break
    # percentage of wins
    return results.count(1.0) / len(results)


def blackjack(n=11):
    env = gym.make('Blackjack-v0')
    results = []
    for i in range(10000):
        state = env.reset()
        while True:
            action = 1 if state[0] <= n else 0
            state, reward, done, info = env.step(action)
            if done:
                results.append(reward)
                break
    return results.count(1.0) / len(results)


def cartpole():
    env = gym.make('CartPole-v0')
    state = env.reset()
    iterations = 0
    while True:
        state, reward, done, info = env.step(int(state[3] > 0))
        iterations += 1
        if done:
            break
    env.close()
    return iterations


def car():
    env = gym.make('MountainCar-v0')
    state = env.reset()
    iterations = 0
    while True:
        if state[1] > 0:
            state, reward, done, info = env.step(2)
        else:
            state, reward, done, info = env.step(0)
        iterations += 1
        if done:
            break
    env.close()
    return iterations


def taxi(q_table):
    env = gym.make('Taxi-v3')
    random_rewards = np.zeros(10000)
    for i in range(10000):
        env.reset()
        while True:
            state, reward, done, info = env.step(env.action_space.sample())
            random_rewards[i] += reward
            if done:
                break
    q_rewards = np.zeros(10000)
    for i in range(10000):
        state = env.reset()
        while True:
            state, reward, done, info = env.step(np.argmax(q_table[state]))
            q_rewards[i] += reward
            if done:
                break
    return np.mean(random_rewards), np.mean(q_rewards)
