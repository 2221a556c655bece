# opengym.py
"""Volume 2: OpenGym AI.
<Name>
<Class>
<Date>

Progress bars everywhere: `tqdm.auto` around every long loop (the way the course's notebooks show
training), `trange` for the Taxi evaluation, and a bar with a running win rate as its postfix.
"""

import gymnasium as gym
import numpy as np
from tqdm import trange
from tqdm.auto import tqdm


def find_qvalues(env, alpha=.1, gamma=.6, epsilon=.1):
    """Use the Q-learning algorithm to find qvalues."""
    env = gym.make(env)
    q_table = np.zeros((env.observation_space.n, env.action_space.n))
    rng = np.random.default_rng()
    for _ in tqdm(range(1, 100001), desc="training", leave=False):
        state, info = env.reset()
        done = False
        while not done:
            if rng.uniform(0, 1) < epsilon:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])
            next_state, reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            old_value = q_table[state, action]
            next_max = np.max(q_table[next_state])
            q_table[state, action] = (1 - alpha) * old_value + alpha * (reward + gamma * next_max)
            state = next_state
    return q_table


# Problem 1
def random_blackjack(n):
    """Play n games of Blackjack with random actions and return the fraction won."""
    env = gym.make("Blackjack-v1")
    wins = 0
    progress = tqdm(range(n), desc="random blackjack")
    for game in progress:
        env.reset()
        done = False
        while not done:
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
            done = terminated or truncated
        if reward == 1:
            wins += 1
        progress.set_postfix(win_rate=f"{wins / (game + 1):.3f}")
    progress.close()
    env.close()
    return wins / n


# Problem 2
def blackjack(n=11):
    """Play 10000 games drawing while the hand is at most n; return the fraction won."""
    env = gym.make("Blackjack-v1")
    wins = 0
    with tqdm(total=10000, desc=f"draw to {n}") as bar:
        for _ in range(10000):
            obs, info = env.reset()
            done = False
            while not done:
                obs, reward, terminated, truncated, info = env.step(1 if obs[0] <= n else 0)
                done = terminated or truncated
            wins += reward == 1
            bar.update(1)
    env.close()
    return wins / 10000


# Problem 3
def cartpole():
    """Balance the pole using the velocity of its tip; return the number of steps."""
    env = gym.make("CartPole-v1")
    obs, info = env.reset()
    steps = 0
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(1 if obs[3] > 0 else 0)
        done = terminated or truncated
        steps += 1
    env.close()
    return steps


# Problem 4
def car():
    """Drive the car up to the flag; return the number of steps."""
    env = gym.make("MountainCar-v0")
    obs, info = env.reset()
    steps = 0
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(2 if obs[1] >= 0 else 0)
        done = terminated or truncated
        steps += 1
    env.close()
    return steps


# Problem 5
def taxi(q_table):
    """Mean total reward of 10000 random episodes and of 10000 episodes following the Q-table."""
    env = gym.make("Taxi-v3")
    naive = []
    for _ in trange(10000, desc="random taxi"):
        env.reset()
        done, total = False, 0
        while not done:
            state, reward, terminated, truncated, info = env.step(env.action_space.sample())
            done = terminated or truncated
            total += reward
        naive.append(total)
    learned = []
    for _ in trange(10000, desc="q-table taxi"):
        state, info = env.reset()
        done, total = False, 0
        while not done:
            state, reward, terminated, truncated, info = env.step(np.argmax(q_table[state]))
            done = terminated or truncated
            total += reward
        learned.append(total)
    env.close()
    return np.mean(naive), np.mean(learned)
