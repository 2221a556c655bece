# Kim Lee -- OpenGym lab
# I put the episode loop in one place so each problem is just a policy.

import gym
import numpy as np


def play(env, choose, start=None):
    # returns number of steps, the summed reward and the reward of the final step
    obs = env.reset() if start is None else start
    total, steps, last = 0.0, 0, 0.0
    finished = False
    while not finished:
        obs, last, finished, _ = env.step(choose(obs))  # one step of the game
        total += last
        steps += 1
    return steps, total, last


def win_rate(policy, games):
    # fraction of blackjack games with a positive final reward
    table = gym.make("Blackjack-v0")
    won = [play(table, policy)[2] > 0 for _ in range(games)]
    table.close()
    return sum(won) / games


def random_blackjack(n):
    # coin flip between hit and stay
    rng = np.random.default_rng()
    return win_rate(lambda obs: int(rng.integers(2)), n)


def blackjack(n=11):
    """Hit when the player's sum is n or lower, otherwise stay. 10k games."""
    return win_rate(lambda obs: int(obs[0] <= n), 10_000)


def cartpole():
    """Move in the direction of the pole's angular velocity; returns the episode length."""
    env = gym.make("CartPole-v0")
    length = play(env, lambda obs: int(obs[3] > 0))[0]
    env.close()
    return length


def car():
    """Push with the velocity (full throttle forward or back)."""
    env = gym.make("MountainCar-v0")
    length = play(env, lambda obs: 2 * int(obs[1] >= 0))[0]
    env.close()
    return length


def taxi(q_table):
    """Average total reward: random actions vs. greedy actions from q_table."""
    env = gym.make("Taxi-v3")
    naive = np.mean([play(env, lambda s: env.action_space.sample())[1] for _ in range(10_000)])
    learned = np.mean([play(env, lambda s: int(np.argmax(q_table[s])))[1] for _ in range(10_000)])
    env.close()
    return naive, learned
