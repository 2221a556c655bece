# opengym.py
"""Volume 2: OpenGym AI.
Dana Whitfield
"""

import gym


def cartpole():
    """Run a fixed 200-step loop and count the steps while the pole was up."""
    env = gym.make("CartPole-v0")
    obs = env.reset()
    upright = 0
    fallen = False
    for t in range(200):
        obs, reward, done, info = env.step(1 if obs[3] > 0 else 0)
        if not fallen:
            upright += 1
        if done:
            fallen = True
    env.close()
    return upright
