import random

import gym
import numpy as np

# Carla Nguyen -- I wrote one small Agent class and reused it for every game.


class Agent:
    def __init__(self, env_name, rule):
        self.env = gym.make(env_name)
        self.rule = rule

    def episode(self):
        state = self.env.reset()
        length, score = 0, 0
        while True:
            state, reward, done, _ = self.env.step(self.rule(state))
            length += 1
            score += reward
            if done:
                return length, score, reward

    def close(self):
        self.env.close()


def random_blackjack(n):
    agent = Agent("Blackjack-v0", lambda state: random.choice([0, 1]))
    results = [agent.episode()[2] for i in range(n)]
    agent.close()
    print("win rate after", n, "games:", results.count(1) / n)
    return results.count(1) / n


def blackjack(n=11):
    agent = Agent("Blackjack-v0", lambda state: 0 if state[0] > n else 1)
    won = sum(agent.episode()[2] == 1 for i in range(10000))
    agent.close()
    return won / 10000


def cartpole():
    agent = Agent("CartPole-v0", lambda state: int(state[3] > 0))
    length = agent.episode()[0]
    agent.close()
    return length


def car():
    def push(state):
        position, speed = state
        return 2 if speed > 0 else 0

    agent = Agent("MountainCar-v0", push)
    length = agent.episode()[0]
    agent.close()
    return length


def taxi(q_table):
    wanderer = Agent("Taxi-v3", lambda state: random.randrange(6))
    greedy = Agent("Taxi-v3", lambda state: np.argmax(q_table[state]))
    first = np.mean([wanderer.episode()[1] for i in range(10000)])
    second = np.mean([greedy.episode()[1] for i in range(10000)])
    wanderer.close()
    greedy.close()
    return first, second
