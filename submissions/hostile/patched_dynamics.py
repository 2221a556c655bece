"""Hostile: monkeypatches CartPole's physics (the pole never falls) and its time limit."""

import gymnasium
from gymnasium.envs.classic_control import cartpole as cartpole_module

_real_step = cartpole_module.CartPoleEnv.step


def _never_falls(self, action):
    observation, reward, terminated, truncated, info = _real_step(self, action)
    self.steps_beyond_terminated = None
    return observation, 1.0, False, truncated, info


def cartpole():
    cartpole_module.CartPoleEnv.step = _never_falls
    gymnasium.envs.registry["CartPole-v0"].max_episode_steps = 1000
    env = gymnasium.make("CartPole-v0")
    env.reset()
    steps = 0
    done = False
    while not done and steps < 500:
        _, _, terminated, truncated, _ = env.step(0)
        steps += 1
        done = terminated or truncated
    return steps


def ok():
    return 42
