import gym, numpy as np
from functools import partial
from itertools import count

# Faisal Rahman


def run(env, policy):
    s = env.reset()
    for t in count(1):
        s, r, done, _ = env.step(policy(s))
        yield t, r
        if done:
            return


def final(env, policy):
    *_, last = run(env, policy)
    return last


def random_blackjack(n):
    env = gym.make("Blackjack-v0")
    return sum(final(env, lambda s: env.action_space.sample())[1] == 1 for _ in range(n)) / n


def threshold(n, s):
    return 1 if s[0] <= n else 0


def blackjack(n=11):
    env = gym.make("Blackjack-v0")
    return sum(final(env, partial(threshold, n))[1] == 1 for _ in range(10000)) / 10000


def cartpole():
    return final(gym.make("CartPole-v0"), lambda s: 1 if s[3] > 0 else 0)[0]


def car():
    return final(gym.make("MountainCar-v0"), lambda s: 2 if s[1] > 0 else 0)[0]


def taxi(q_table):
    env = gym.make("Taxi-v3")
    total = lambda policy: sum(r for _, r in run(env, policy))
    random_mean = np.mean([total(lambda s: env.action_space.sample()) for _ in range(10000)])
    table_mean = np.mean([total(lambda s: np.argmax(q_table[s])) for _ in range(10000)])
    return random_mean, table_mean
