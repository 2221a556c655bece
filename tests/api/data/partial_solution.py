# ruff: noqa: RUF059, SIM108  (kept as the lab-literal solution wrote it)
"""Part of the lab-literal solution (submissions/classic_complete.py): Problems 1, 3 and 4 only.

A quick real grading for the service's end-to-end tests: three problems pass, the others are missing.
"""

import gym


def random_blackjack(n):
    """Play n games of Blackjack with random actions.

    Parameters:
        n (int): how many games to play

    Returns:
        (float): the fraction of the n games that the player won
    """
    env = gym.make("Blackjack-v0")
    wins = 0
    for _ in range(n):
        env.reset()
        done = False
        while not done:
            # take random actions until the game is over
            observation, reward, done, info = env.step(env.action_space.sample())
        if reward == 1:
            wins += 1
    env.close()
    return wins / n


def cartpole():
    """Balance the pole in CartPole-v0 using the velocity of its tip.

    Returns:
        (int): the number of steps before the episode ended
    """
    env = gym.make("CartPole-v0")
    try:
        obs = env.reset()
        done = False
        iterations = 0
        while not done:
            # push the cart the way the tip of the pole is moving
            if obs[3] > 0:
                action = 1
            else:
                action = 0
            obs, reward, done, info = env.step(action)
            iterations += 1
    finally:
        env.close()
    return iterations


def car():
    """Drive the car in MountainCar-v0 up to the flag.

    Returns:
        (int): the number of steps it took
    """
    env = gym.make("MountainCar-v0")
    try:
        obs = env.reset()
        done = False
        iterations = 0
        while not done:
            # accelerate in the direction the car is already moving
            if obs[1] >= 0:
                action = 2
            else:
                action = 0
            obs, reward, done, info = env.step(action)
            iterations += 1
    finally:
        env.close()
    return iterations
