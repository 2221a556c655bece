"""OpenGym lab -- Brandon Mireles, section 2."""

import gym
import numpy as np


def play(env, choose, start=None):
    """Run one episode with the policy `choose(observation)`; return (steps, total reward, last reward)."""
    obs = env.reset() if start is None else start
    total, steps, last = 0.0, 0, 0.0
    finished = False
    while not finished:
        obs, last, finished, _ = env.step(choose(obs))
        total += last
        steps += 1
    return steps, total, last


def win_rate(policy, games):
    table = gym.make("Blackjack-v0")
    won = [play(table, policy)[2] > 0 for _ in range(games)]
    table.close()
    return sum(won) / games


def random_blackjack(n):
    """Random blackjack: share of n games won."""
    rng = np.random.default_rng()
    return win_rate(lambda obs: int(rng.integers(2)), n)


def blackjack(n=11):
    """Threshold strategy: draw on n or less."""
    return win_rate(lambda obs: int(obs[0] <= n), 10_000)


def cartpole():
    env = gym.make("CartPole-v0")
    length = play(env, lambda obs: int(obs[3] > 0))[0]
    env.close()
    return length


def car():
    env = gym.make("MountainCar-v0")
    length = play(env, lambda obs: 2 * int(obs[1] >= 0))[0]
    env.close()
    return length


def taxi(q_table):
    env = gym.make("Taxi-v3")
    naive = np.mean([play(env, lambda s: env.action_space.sample())[1] for _ in range(10_000)])
    learned = np.mean([play(env, lambda s: int(np.argmax(q_table[s])))[1] for _ in range(10_000)])
    env.close()
    return naive, learned
