# opengym.py
"""Volume 2: OpenGym AI.
Jordan Alvarez
Math 321
Winter 2021
"""

import gym
import numpy as np
import IPython
from IPython.display import HTML, Markdown, clear_output, display
from IPython.core.display import Image  # noqa: F401  (kept from an earlier cell)


def _in_notebook():
    """True inside Jupyter, False when run as a script."""
    shell = IPython.get_ipython()
    return shell is not None and "IPKernelApp" in shell.config


def random_blackjack(n):
    """Play n random games of Blackjack and return the share of wins."""
    env = gym.make("Blackjack-v0")
    wins = 0
    for game in range(n):
        env.reset()
        done = False
        while not done:
            obs, reward, done, info = env.step(env.action_space.sample())
        wins += reward > 0
        if _in_notebook() and game % 1000 == 0:
            clear_output(wait=True)
            display(HTML(f"<b>game {game}</b>: {wins} wins"))
    env.close()
    display(Markdown(f"**{wins} wins** in {n} games"))
    return wins / n


def car():
    """Swing up to the flag: push in the direction the car already moves."""
    env = gym.make("MountainCar-v0")
    obs = env.reset()
    steps, done = 0, False
    while not done:
        obs, reward, done, info = env.step(2 if obs[1] >= 0 else 0)
        steps += 1
    env.close()
    display(HTML(f"<p>{steps} steps, IPython {IPython.__version__}</p>"))
    return steps
