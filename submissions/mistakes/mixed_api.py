"""A function that unpacks reset() the gym 0.26 way and step() the classic way: no gym version runs it."""

import gym


def cartpole():
    env = gym.make("CartPole-v1")
    obs, info = env.reset()
    done = False
    steps = 0
    while not done:
        obs, reward, done, info = env.step(1 if obs[3] > 0 else 0)
        steps += 1
    return steps
