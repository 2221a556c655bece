"""Reinforcement learning lab, gymnasium edition. Elena Petrova."""
import gymnasium as gym
import numpy as np
import random


def random_blackjack(n):
    env = gym.make("Blackjack-v1", sab=True)
    won = 0
    for _ in range(n):
        observation, info = env.reset()
        terminated = truncated = False
        while not (terminated or truncated):
            observation, reward, terminated, truncated, info = env.step(env.action_space.sample())
        won += reward > 0
    env.close()
    return won / n


def blackjack(n=11):
    env = gym.make("Blackjack-v1", sab=True)
    won = 0
    for _ in range(10_000):
        (player, dealer, usable), info = env.reset()
        terminated = truncated = False
        while not (terminated or truncated):
            hit = player <= n
            (player, dealer, usable), reward, terminated, truncated, info = env.step(int(hit))
        won += reward > 0
    env.close()
    return won / 10_000


def cartpole(render=False):
    env = gym.make("CartPole-v1", render_mode="human" if render else None)
    (x, x_dot, theta, theta_dot), info = env.reset()
    steps = 0
    while True:
        # the tip moves with the angular velocity, so follow it
        (x, x_dot, theta, theta_dot), reward, terminated, truncated, info = env.step(int(theta_dot > 0))
        steps += 1
        if terminated or truncated:
            break
    env.close()
    return steps


def car(render=False):
    env = gym.make("MountainCar-v0", render_mode="human" if render else None)
    (position, velocity), info = env.reset()
    steps = 0
    while True:
        push = 2 if velocity >= 0 else 0
        (position, velocity), reward, terminated, truncated, info = env.step(push)
        steps += 1
        if terminated or truncated:
            break
    env.close()
    return steps


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta


def taxi(q_table, q_table_decay):
    env = gym.make("Taxi-v3")
    means = []
    for table in (q_table, q_table_decay):
        totals = []
        for _ in range(1000):
            state, info = env.reset()
            total = 0
            terminated = truncated = False
            while not (terminated or truncated):
                state, reward, terminated, truncated, info = env.step(int(np.argmax(table[state])))
                total += reward
            totals.append(total)
        means.append(sum(totals) / len(totals))
    env.close()
    return means[0], means[1]
