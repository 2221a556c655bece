# gymnasium.py
"""Reinforcement Learning 1: Gymnasium, problems 3 and 4 only: the student left render=True as the default,
so the grader's cartpole() and car() calls make the envs with render_mode="human" and render every step.
There is no display in the sandbox: the flag must change nothing but the drawing."""

import gymnasium as gym


# Problem 3
def cartpole(render=True):
    """Timesteps CartPole-v1 lasts pushing the way the tip of the pole moves."""
    env = gym.make("CartPole-v1", render_mode="human" if render else None)
    observation, _ = env.reset()
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(1 if observation[3] > 0 else 0)
        done = terminated or truncated
        steps += 1
        if render:
            env.render()
    env.close()
    return steps


# Problem 4
def car(render=True):
    """Timesteps MountainCar-v0 takes to reach the flag, accelerating the way the car moves."""
    env = gym.make("MountainCar-v0", render_mode="human" if render else None)
    observation, _ = env.reset()
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(2 if observation[1] >= 0 else 0)
        done = terminated or truncated
        steps += 1
        if render:
            env.render()
    env.close()
    return steps
