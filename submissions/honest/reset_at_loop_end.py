# opengym.py
"""Volume 2: OpenGym AI.
Robin Patel
"""

import gym


def random_blackjack(n):
    env = gym.make("Blackjack-v0")
    env.reset()
    win = 0
    for i in range(n):
        done = False
        while not done:
            obs, reward, done, info = env.step(env.action_space.sample())
        if reward > 0:
            win += 1
        env.reset()
    env.close()
    return win / n


def blackjack(n=11):
    env = gym.make("Blackjack-v0")
    obs = env.reset()
    win = 0
    for i in range(10000):
        done = False
        while not done:
            obs, reward, done, info = env.step(1 if obs[0] <= n else 0)
        win += reward > 0
        obs = env.reset()
    env.close()
    return win / 10000
