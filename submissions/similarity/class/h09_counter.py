from collections import Counter

import gym
import numpy as np

# Hiro Tanaka. Counter keeps the tallies of wins, draws and losses.


def _tally(policy, games):
    env = gym.make("Blackjack-v0")
    outcomes = Counter()
    for _ in range(games):
        state = env.reset()
        while True:
            state, reward, done, _ = env.step(policy(state))
            if done:
                outcomes[{1: "win", 0: "draw", -1: "loss"}[int(reward)]] += 1
                break
    env.close()
    return outcomes


def random_blackjack(n):
    outcomes = _tally(lambda state: np.random.choice(2), n)
    return outcomes["win"] / n


def blackjack(n=11):
    outcomes = _tally(lambda state: int(state[0] <= n), 10000)
    return outcomes["win"] / sum(outcomes.values())


def _balance(env_name, decide):
    env = gym.make(env_name)
    state = env.reset()
    for step in range(1, 10**6):
        state, _, done, _ = env.step(decide(state))
        if done:
            env.close()
            return step
    return -1


def cartpole():
    return _balance("CartPole-v0", lambda state: int(state[3] >= 0))


def car():
    return _balance("MountainCar-v0", lambda state: 0 if state[1] < 0 else 2)


def taxi(q_table):
    env = gym.make("Taxi-v3")
    sums = Counter()
    for name in ("random", "table"):
        for _ in range(10000):
            state = env.reset()
            done = False
            while not done:
                move = env.action_space.sample() if name == "random" else int(np.argmax(q_table[state]))
                state, reward, done, _ = env.step(move)
                sums[name] += reward
    env.close()
    return sums["random"] / 10000, sums["table"] / 10000
