"""A public gymnasium solution (independent of every student here)."""
import gymnasium as gym
import numpy as np


def simulate(env, policy, episodes):
    rewards, lengths = [], []
    for _ in range(episodes):
        obs, _ = env.reset()
        total, length, end = 0.0, 0, False
        while not end:
            obs, reward, terminated, truncated, _ = env.step(policy(obs))
            total += reward
            length += 1
            end = terminated or truncated
        rewards.append(total)
        lengths.append(length)
    return np.array(rewards), np.array(lengths)


def random_blackjack(n):
    env = gym.make("Blackjack-v1")
    rewards, _ = simulate(env, lambda obs: env.action_space.sample(), n)
    return float(np.mean(rewards > 0))


def blackjack(n=11):
    env = gym.make("Blackjack-v1")
    rewards, _ = simulate(env, lambda obs: int(obs[0] <= n), 10000)
    return float(np.mean(rewards > 0))


def cartpole(render=False):
    _, lengths = simulate(gym.make("CartPole-v1"), lambda obs: int(obs[3] > 0), 1)
    return int(lengths[0])


def car(render=False):
    _, lengths = simulate(gym.make("MountainCar-v0"), lambda obs: 2 if obs[1] > 0 else 0, 1)
    return int(lengths[0])


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start - (episode - 1) * ((epsilon_start - epsilon_end) / N)


def taxi(q_table, q_table_decay):
    env = gym.make("Taxi-v3")
    constant, _ = simulate(env, lambda s: int(np.argmax(q_table[s])), 1000)
    decaying, _ = simulate(env, lambda s: int(np.argmax(q_table_decay[s])), 1000)
    return float(constant.mean()), float(decaying.mean())
