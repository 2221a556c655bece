# OpenGym AI lab, Quentin Moreau
import gym
import numpy as np

LIMIT = 1000


def episode(environment, policy):
    """Plays until the game ends (or LIMIT) and returns the list of rewards we recieve."""
    state = environment.reset()
    rewards = []
    for _ in range(LIMIT):
        state, r, finished, _ = environment.step(policy(state))
        rewards.append(r)
        if finished:
            break
    return rewards


def random_blackjack(n):
    environment = gym.make("Blackjack-v0")
    # last reward of each game tells us who won
    last = np.array([episode(environment, lambda s: np.random.choice([0, 1]))[-1] for _ in range(n)])
    return np.mean(last == 1)


def blackjack(n=11):
    environment = gym.make("Blackjack-v0")
    last = np.array([episode(environment, lambda s: 1 if s[0] <= n else 0)[-1] for _ in range(10000)])
    return np.mean(last == 1)


def cartpole():
    environment = gym.make("CartPole-v0")
    return len(episode(environment, lambda s: 1 if s[3] > 0 else 0))


def car():
    environment = gym.make("MountainCar-v0")
    return len(episode(environment, lambda s: 0 if s[1] < 0 else 2))


def taxi(q_table):
    environment = gym.make("Taxi-v3")
    rand = [sum(episode(environment, lambda s: environment.action_space.sample())) for _ in range(10000)]
    greedy = [sum(episode(environment, lambda s: np.argmax(q_table[s]))) for _ in range(10000)]
    return np.mean(rand), np.mean(greedy)
