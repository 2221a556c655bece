# opengym.py
"""Volume 2: OpenGym AI.
Taylor Nguyen
Math 321
Fall 2020
"""

import gym
import numpy as np
from IPython.display import clear_output
import time


def cartpole():
    """Balance the pole, drawing every frame."""
    env = gym.make("CartPole-v0")
    try:
        obs = env.reset()
        done = False
        iterations = 0
        while not done:
            env.render()
            obs, reward, done, info = env.step(1 if obs[3] > 0 else 0)
            iterations += 1
            clear_output(wait=True)
            print("step", iterations)
    finally:
        env.close()
    return iterations


def car():
    """Swing up to the flag, drawing every frame."""
    env = gym.make("MountainCar-v0")
    obs = env.reset()
    steps = 0
    done = False
    while not done:
        env.render(mode="human")
        obs, reward, done, info = env.step(2 if obs[1] >= 0 else 0)
        steps += 1
        if steps % 20 == 0:
            clear_output(wait=True)
            print(f"position {obs[0]:.3f}")
    env.close()
    return steps
