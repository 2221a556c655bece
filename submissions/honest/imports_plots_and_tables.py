# opengym.py
"""Volume 2: OpenGym AI.
<Name>
<Class>
<Date>

Written the way a notebook-trained student writes a .py file: pandas tables of every run, scipy for a
confidence interval, matplotlib figures drawn (and "shown") inside the functions, IPython's display and
clear_output for live updates, and the classic gym API with `Blackjack-v0`.
"""

import gym
import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import clear_output, display
from scipy import stats

matplotlib.rcParams["figure.figsize"] = (8, 4)


# Problem 1
def random_blackjack(n):
    """Play n games of Blackjack with random actions; return the fraction won (with a 95% CI printed)."""
    env = gym.make("Blackjack-v0")
    results = []
    for i in range(n):
        env.reset()
        done = False
        while not done:
            obs, reward, done, info = env.step(env.action_space.sample())
        results.append(reward)
    env.close()
    games = pd.DataFrame({"reward": results})
    games["won"] = games["reward"] == 1
    display(games["reward"].value_counts().to_frame("games"))
    wins = int(games["won"].sum())
    interval = stats.binomtest(wins, n).proportion_ci(confidence_level=0.95)
    print(f"win rate {wins / n:.3f}, 95% CI ({interval.low:.3f}, {interval.high:.3f})")
    return games["won"].mean()


# Problem 2
def blackjack(n=11):
    """Play 10000 games drawing while the hand is at most n; plot the running win rate; return it."""
    env = gym.make("Blackjack-v0")
    rewards = np.zeros(10000)
    for game in range(10000):
        obs = env.reset()
        done = False
        while not done:
            if obs[0] <= n:
                obs, reward, done, info = env.step(1)
            else:
                obs, reward, done, info = env.step(0)
        rewards[game] = reward
        if game % 2000 == 0:
            clear_output(wait=True)
            print(f"n = {n}: game {game}")
    env.close()
    running = pd.Series(rewards == 1).expanding().mean()
    fig, ax = plt.subplots()
    running.plot(ax=ax, title=f"draw while <= {n}")
    ax.set_xlabel("game")
    ax.set_ylabel("win rate so far")
    plt.show()
    plt.close(fig)
    return float(np.mean(rewards == 1))


# Problem 3
def cartpole():
    """Balance the pole using the velocity of its tip; return the number of steps survived."""
    env = gym.make("CartPole-v0")
    obs = env.reset()
    done = False
    steps = 0
    angles = []
    while not done:
        obs, reward, done, info = env.step(1 if obs[3] > 0 else 0)
        angles.append(obs[2])
        steps += 1
    env.close()
    plt.figure()
    plt.plot(np.degrees(angles))
    plt.title("pole angle (degrees)")
    plt.show()
    return steps


# Problem 4
def car():
    """Drive the car up to the flag; return the number of steps."""
    env = gym.make("MountainCar-v0")
    obs = env.reset()
    done = False
    steps = 0
    path = []
    while not done:
        obs, reward, done, info = env.step(2 if obs[1] >= 0 else 0)
        path.append(obs)
        steps += 1
    env.close()
    display(pd.DataFrame(path, columns=["position", "velocity"]).describe())
    return steps


# Problem 5
def taxi(q_table):
    """Mean total reward of 10000 random episodes and of 10000 episodes following the Q-table."""
    env = gym.make("Taxi-v3")
    totals = {"random": [], "q_table": []}
    for policy in totals:
        for _ in range(10000):
            state = env.reset()
            done = False
            total = 0
            while not done:
                action = env.action_space.sample() if policy == "random" else np.argmax(q_table[state])
                state, reward, done, info = env.step(action)
                total += reward
            totals[policy].append(total)
    env.close()
    summary = pd.DataFrame(totals).agg(["mean", "std"])
    display(summary)
    return summary.loc["mean", "random"], summary.loc["mean", "q_table"]
