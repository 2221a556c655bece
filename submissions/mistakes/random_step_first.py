"""gym 0.26 code with the lab-era counting pattern: reset, one random step, then count the loop's steps.

The policies are right; every returned count is one short of the episode actually played.
"""

import gym


def cartpole():
    env = gym.make("CartPole-v1")
    obs, info = env.reset()
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    steps = 0
    while not (terminated or truncated):
        obs, reward, terminated, truncated, info = env.step(1 if obs[3] > 0 else 0)
        steps += 1
    return steps


def car():
    env = gym.make("MountainCar-v0")
    obs, info = env.reset()
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    steps = 0
    while not (terminated or truncated):
        obs, reward, terminated, truncated, info = env.step(2 if obs[1] >= 0 else 0)
        steps += 1
    return steps
