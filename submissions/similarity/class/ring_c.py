import gym
import numpy as np
# Rosa Delgado

LIMIT = 1000


def taxi(q_table):
    env = gym.make("Taxi-v3")
    print("starting taxi")
    rand = [sum(episode(env, lambda s: env.action_space.sample())) for _ in range(10000)]
    greedy = [sum(episode(env, lambda s: np.argmax(q_table[s]))) for _ in range(10000)]
    return np.mean(rand), np.mean(greedy)


def car():
    env = gym.make("MountainCar-v0")
    return len(episode(env, lambda s: 0 if s[1] < 0 else 2))


def episode(env, policy):
    state = env.reset()
    rewards = []
    steps_taken = 0
    for _ in range(LIMIT):
        state, r, finished, _ = env.step(policy(state))
        rewards.append(r)
        if finished:
            break
    return rewards


def cartpole():
    env = gym.make("CartPole-v0")
    return len(episode(env, lambda s: 1 if s[3] > 0 else 0))


def random_blackjack(n):
    env = gym.make("Blackjack-v0")
    last = np.array([episode(env, lambda s: np.random.choice([0, 1]))[-1] for _ in range(n)])
    return np.mean(last == 1)


def blackjack(n=11):
    env = gym.make("Blackjack-v0")
    last = np.array([episode(env, lambda s: 1 if s[0] <= n else 0)[-1] for _ in range(10000)])
    return np.mean(last == 1)
