"""Reinforcement Learning 1: Gymnasium -- Ivan Horvat (the current edition, problems 5 to 7)."""
import gymnasium as gym
import numpy as np
import random


def random_blackjack(n):
    env = gym.make("Blackjack-v1")
    wins = 0
    for _ in range(n):
        env.reset()
        over = False
        while not over:
            _, reward, terminated, truncated, _ = env.step(random.choice((0, 1)))
            over = terminated or truncated
        wins += int(reward == 1)
    return wins / n


def blackjack(n=11):
    env = gym.make("Blackjack-v1")
    wins = 0
    for _ in range(10000):
        obs, _ = env.reset()
        over = False
        while not over:
            obs, reward, terminated, truncated, _ = env.step(0 if obs[0] > n else 1)
            over = terminated or truncated
        wins += int(reward == 1)
    return wins / 10000


def cartpole(render=False):
    env = gym.make("CartPole-v1")
    obs, _ = env.reset()
    for t in range(1, 501):
        obs, _, terminated, truncated, _ = env.step(1 if obs[3] > 0 else 0)
        if terminated or truncated:
            return t
    return 500


def car(render=False):
    env = gym.make("MountainCar-v0")
    obs, _ = env.reset()
    for t in range(1, 201):
        obs, _, terminated, truncated, _ = env.step(2 if obs[1] > 0 else 0)
        if terminated or truncated:
            return t
    return 200


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


def choose(q_table, state, epsilon, env):
    if random.uniform(0, 1) < epsilon:
        return env.action_space.sample()
    return int(np.argmax(q_table[state]))


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    table = np.zeros((env.observation_space.n, env.action_space.n))
    penalties = 0
    for episode in range(1, N + 1):
        eps = epsilon_decay(episode, N) if decay else epsilon
        state, _ = env.reset()
        action = choose(table, state, eps, env)
        done = False
        while not done:
            following, reward, done, _, _ = env.step(action)
            next_action = choose(table, following, eps, env)
            table[state, action] += alpha * (reward + gamma * table[following, next_action] - table[state, action])
            penalties += reward == -10
            state, action = following, next_action
    env.close()
    return table, penalties


def taxi(q_table, q_table_decay):
    env = gym.make("Taxi-v3")
    results = []
    for table in (q_table, q_table_decay):
        total = 0
        for _ in range(1000):
            state, _ = env.reset()
            over = False
            while not over:
                state, reward, terminated, truncated, _ = env.step(int(np.argmax(table[state])))
                total += reward
                over = terminated or truncated
        results.append(total / 1000)
    return tuple(results)
