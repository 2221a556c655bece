# opengym.py
"""Volume 2: OpenGym AI.
Chris Baker
Math 321
"""

import gym


def car():
    """Drive up the hill; returns the iterations it took."""
    env = gym.make("MountainCar-v0")
    env.reset()
    obs, reward, done, info = env.step(env.action_space.sample())  # take one step to get the velocity
    iterations = 0
    while not done:
        if obs[1] < 0:
            obs, reward, done, info = env.step(0)
        else:
            obs, reward, done, info = env.step(2)
        iterations += 1
    env.close()
    return iterations
