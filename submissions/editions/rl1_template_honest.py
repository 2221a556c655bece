# gymnasium.py
"""Volume 2: Reinforcement Learning 1 - Gymnasium.
C. Student
Math 321
November 2025

The course's gymnasium.ipynb written as a module: the functions at the top level, the notebook's other cells
(the demos and the training of the tables compare() reads) under `if __name__ == "__main__":`.
"""

import gymnasium as gym
import numpy as np
import random
from matplotlib import pyplot as plt
from IPython import display


# Problem 1
def random_blackjack(n):
    """ Play n games of Blackjack-v1 with random actions and return the fraction won.
    Parameters:
        n (int): number of episodes
    Returns:
        percent (float): fraction of the episodes the player won
    """
    env = gym.make("Blackjack-v1")
    wins = 0
    for _ in range(n):
        state, info = env.reset()
        done = False
        while not done:
            state, reward, terminated, truncated, info = env.step(env.action_space.sample())
            done = terminated or truncated
        if reward > 0:
            wins += 1
    env.close()
    return wins / n


# Problem 2
def blackjack(n=11):
    """ Play 10 000 games of Blackjack-v1, drawing while the hand is at most n.
    Parameters:
        n (int): maximum accepted player hand
    Return:
        percent (float): fraction of the 10 000 episodes won
    """
    env = gym.make("Blackjack-v1")
    wins = 0
    for _ in range(10_000):
        (hand, dealer, usable), info = env.reset()
        done = False
        while not done:
            action = 1 if hand <= n else 0
            (hand, dealer, usable), reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
        if reward > 0:
            wins += 1
    env.close()
    return wins / 10_000


# Problem 3
def cartpole(render=False):
    """ Keep CartPole-v1 up by pushing the way the tip of the pole moves.
    Parameters:
        render (bool): If True, render environment at each step
    Return:
        iterations (integer): number of timesteps the episode lasted
    """
    env = gym.make("CartPole-v1", render_mode="human" if render else None)
    state, info = env.reset()
    steps, done = 0, False
    while not done:
        action = 1 if state[3] > 0 else 0
        state, reward, terminated, truncated, info = env.step(action)
        steps += 1
        done = terminated or truncated
    env.close()
    return steps


# Problem 4
def car(render=False):
    """ Drive MountainCar-v0 to the flag, accelerating the way the car moves.
    Parameters:
        render (bool): If True, render environment at each step
    Return:
        iterations (integer): number of timesteps to reach the flag
    """
    env = gym.make("MountainCar-v0", render_mode="human" if render else None)
    (position, velocity), info = env.reset()
    steps, done = 0, False
    while not done:
        action = 2 if velocity >= 0 else 0
        (position, velocity), reward, terminated, truncated, info = env.step(action)
        steps += 1
        done = terminated or truncated
    env.close()
    return steps


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    """ Linear decay of epsilon over N episodes.
    Parameters:
        episode (int): current episode number (from 1)
        N (int): total number of episodes
        epsilon_start (float): starting epsilon value
        epsilon_end (float): ending epsilon value
    Returns:
        epsilon (float): decayed epsilon value
    """
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta


def qlearn(env, alpha=.1, gamma=.6, epsilon=.1, N=70_000, decay=False):
    """ Q-learning (given by the template).
    Parameters:
        env (str): environment name (a gym environment id)
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): epsilon of the epsilon-greedy behaviour
        N (int): number of training episodes
        decay (bool): whether episode i explores with epsilon_decay(i, N)
    Returns:
        q_table (ndarray nxm): the Q-table
        penalties (int): rewards of -10 taken
    """
    env = gym.make(env)
    q_table = np.zeros((env.observation_space.n, env.action_space.n))
    penalties = 0
    for i in range(1, N + 1):
        state, info = env.reset()
        rate = epsilon_decay(i, N) if decay else epsilon
        done = False
        while not done:
            if random.uniform(0, 1) < rate:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])
            next_state, reward, done, truncated, info = env.step(action)
            old_value = q_table[state, action]
            next_max = q_table[next_state].max()
            q_table[state, action] = (1 - alpha) * old_value + alpha * (reward + gamma * next_max)
            if reward == -10:
                penalties += 1
            state = next_state
        if i % 100 == 0:
            display.clear_output(wait=True)
            print(f"Episode: {i}")
    env.close()
    print("Training finished.")
    return q_table, penalties


def taxi(q_table, q_table_decay):
    """ Mean total reward of 1 000 greedy Taxi-v3 episodes with each table.
    Parameters:
        q_table (ndarray nxm): table of qvalues that used constant epsilon
        q_table_decay (ndarray nxm): table of qvalues that used a decaying epsilon
    Returns:
        constant_reward (float): mean reward with q_table
        decay_reward (float): mean reward with q_table_decay
    """
    env = gym.make("Taxi-v3")
    means = []
    for table in (q_table, q_table_decay):
        totals = []
        for _ in range(1000):
            state, info = env.reset()
            total, done = 0, False
            while not done:
                state, reward, terminated, truncated, info = env.step(np.argmax(table[state]))
                total += reward
                done = terminated or truncated
            totals.append(total)
        means.append(np.mean(totals))
    env.close()
    return means[0], means[1]


def sarsa0(env, alpha=0.1, gamma=0.6, epsilon=0.1, N=70_000, decay=False):
    """ SARSA(0) on the environment named env.
    Parameters:
        env (str): environment name (a gym environment id)
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): epsilon of the epsilon-greedy behaviour
        N (int): number of training episodes
        decay (bool): whether episode i explores with epsilon_decay(i, N)
    Returns:
        q_table (ndarray nxm): the Q-table SARSA(0) learned
    """
    env = gym.make(env)
    q_table = np.zeros((env.observation_space.n, env.action_space.n))

    def choose(state, rate):
        if random.uniform(0, 1) < rate:
            return env.action_space.sample()
        return np.argmax(q_table[state])

    for i in range(1, N + 1):
        rate = epsilon_decay(i, N) if decay else epsilon
        state, info = env.reset()
        action = choose(state, rate)
        done = False
        while not done:
            next_state, reward, done, truncated, info = env.step(action)
            next_action = choose(next_state, rate)
            target = reward + gamma * q_table[next_state, next_action]
            q_table[state, action] += alpha * (target - q_table[state, action])
            state, action = next_state, next_action
        if i % 100 == 0:
            display.clear_output(wait=True)
            print(f"Episode: {i}")
    env.close()
    return q_table


def compare():
    """ Mean total reward of 1 000 greedy Taxi-v3 episodes with the decaying-epsilon Q-learning table and
    with the SARSA table.
    Returns:
        q_reward (float): mean reward with the Q-learning table
        sarsa_reward (float): mean reward with the SARSA table
    """
    env = gym.make("Taxi-v3")
    means = []
    for table in (q_table_decay, sarsa_table_decay):
        totals = []
        for _ in range(1000):
            state, info = env.reset()
            total, done = 0, False
            while not done:
                state, reward, terminated, truncated, info = env.step(np.argmax(table[state]))
                total += reward
                done = terminated or truncated
            totals.append(total)
        means.append(np.mean(totals))
    env.close()
    return means[0], means[1]


if __name__ == "__main__":
    print(f"Won {100 * random_blackjack(50_000):.2f}% of 50,000 random games")
    ns = np.arange(1, 22)
    rates = [blackjack(n) for n in ns]
    plt.plot(ns, rates, marker="o")
    plt.xlabel("n")
    plt.ylabel("win rate")
    plt.title("Blackjack: draw while the hand is at most n")
    plt.show()
    print("Best n:", ns[int(np.argmax(rates))])
    print("Average steps:", np.mean([cartpole() for _ in range(100)]))
    print("Average steps:", np.mean([car() for _ in range(100)]))
    env = gym.make("Taxi-v3")
    state, info = env.reset()
    total, done = 0, False
    while not done:
        state, reward, terminated, truncated, info = env.step(env.action_space.sample())
        total += reward
        done = terminated or truncated
    env.close()
    print("Total reward of a random episode:", total)
    q_table, _ = qlearn("Taxi-v3")
    q_table_decay, _ = qlearn("Taxi-v3", decay=True)
    print(taxi(q_table, q_table_decay))
    sarsa_table_decay = sarsa0("Taxi-v3", decay=True)
    print(compare())
