# opengym.py
"""Volume 2: OpenGym AI.
B. Student
Math 321
February 2023

A complete solution of the later notebook version of the lab, as written for gym 0.26: `import gym` and
`import gym_toytext`, `obs, info = env.reset()`, five-value `env.step`, `render_mode=` in `gym.make`, and
the ids that version names (`Blackjack-v1`, `CartPole-v1`, `MountainCar-v0`, `Taxi-v3`).
"""

import random

import gym
import gym_toytext  # noqa: F401  (registers NChain-v0 and GuessingGame-v0, which gym 0.26 dropped)
import numpy as np
from IPython.display import clear_output


def find_qvalues(env, alpha=.1, gamma=.6, epsilon=.1):
    """
    Use the Q-learning algorithm to find qvalues.

    Parameters:
        env (str): environment name
        alpha (float): learning rate
        gamma (float): discount factor
        epsilon (float): maximum value

    Returns:
        q_table (ndarray nxm)
    """
    # Make environment
    env = gym.make(env)
    # Make Q-table
    q_table = np.zeros((env.observation_space.n, env.action_space.n))

    # Train
    for i in range(1, 100001):
        # Reset state
        state, info = env.reset()

        epochs, penalties, reward, = 0, 0, 0
        terminated = truncated = False

        while not (terminated or truncated):
            # Accept based on alpha
            if random.uniform(0, 1) < epsilon:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])

            # Take action
            next_state, reward, terminated, truncated, info = env.step(action)

            # Calculate new qvalue
            old_value = q_table[state, action]
            next_max = np.max(q_table[next_state])

            new_value = (1 - alpha) * old_value + alpha * (reward + gamma * next_max)
            q_table[state, action] = new_value

            # Check if penalty is made
            if reward == -10:
                penalties += 1

            # Get next observation
            state = next_state
            epochs += 1

        # Print episode number
        if i % 100 == 0:
            clear_output(wait=True)
            print(f"Episode: {i}")

    print("Training finished.")
    return q_table


# Problem 1
def random_blackjack(n):
    """Play n games of Blackjack with random actions.

    Parameters:
        n (int): how many games to play

    Returns:
        (float): the percentage of the n games that the player won
    """
    env = gym.make("Blackjack-v1")
    wins = 0
    for i in range(n):
        observation, info = env.reset()
        terminated = truncated = False
        while not (terminated or truncated):
            observation, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if reward > 0:
            wins += 1
    env.close()
    return 100 * wins / n


# Problem 2
def blackjack(n=11):
    """Play 10000 games of Blackjack, drawing while the hand is at most n.

    Parameters:
        n (int): the largest hand on which the player still draws

    Returns:
        (float): the percentage of the 10000 games that the player won
    """
    env = gym.make("Blackjack-v1")
    wins = 0
    for i in range(10000):
        observation, info = env.reset()
        terminated = truncated = False
        while not (terminated or truncated):
            action = 1 if observation[0] <= n else 0
            observation, reward, terminated, truncated, info = env.step(action)
        if reward > 0:
            wins += 1
    env.close()
    return 100 * wins / 10000


# Problem 3
def cartpole():
    """Balance the pole in CartPole-v1 using the velocity of its tip.

    Returns:
        (int): the number of steps before the episode ended
    """
    env = gym.make("CartPole-v1", render_mode="rgb_array")
    try:
        obs, info = env.reset()
        steps = 0
        while True:
            # push the cart the way the tip of the pole is moving
            action = 1 if obs[3] > 0 else 0
            obs, reward, terminated, truncated, info = env.step(action)
            steps += 1
            if terminated or truncated:
                break
    finally:
        env.close()
    return steps


# Problem 4
def car():
    """Drive the car in MountainCar-v0 up to the flag.

    Returns:
        (int): the number of steps it took
    """
    env = gym.make("MountainCar-v0", render_mode="rgb_array")
    try:
        obs, info = env.reset()
        steps = 0
        terminated = truncated = False
        while not (terminated or truncated):
            # accelerate in the direction the car is already moving
            action = 2 if obs[1] >= 0 else 0
            obs, reward, terminated, truncated, info = env.step(action)
            steps += 1
    finally:
        env.close()
    return steps


# Problem 5
def taxi(q_table):
    """Compare random actions with the actions of a Q-table in Taxi-v3.

    Parameters:
        q_table (ndarray): the Q-table from find_qvalues

    Returns:
        (float): mean total reward of 10000 random episodes
        (float): mean total reward of 10000 episodes following the Q-table
    """
    env = gym.make("Taxi-v3")

    # random actions
    naive_rewards = []
    for i in range(10000):
        state, info = env.reset()
        terminated = truncated = False
        total_reward = 0
        while not (terminated or truncated):
            state, reward, terminated, truncated, info = env.step(env.action_space.sample())
            total_reward += reward
        naive_rewards.append(total_reward)

    # actions from the Q-table
    q_rewards = []
    for i in range(10000):
        state, info = env.reset()
        terminated = truncated = False
        total_reward = 0
        while not (terminated or truncated):
            action = np.argmax(q_table[state])
            state, reward, terminated, truncated, info = env.step(action)
            total_reward += reward
        q_rewards.append(total_reward)

    env.close()
    return np.mean(naive_rewards), np.mean(q_rewards)


if __name__ == "__main__":
    from matplotlib import pyplot as plt

    env = gym.make("NChain-v0")
    print(env.reset())
    env.close()

    print("Random blackjack win percentage:", random_blackjack(500))

    domain = np.arange(1, 22)
    win_rates = [blackjack(n) for n in domain]
    plt.plot(domain, win_rates)
    plt.show()

    env = gym.make("CartPole-v1", render_mode="human")
    obs, info = env.reset()
    terminated = truncated = False
    while not (terminated or truncated):
        obs, reward, terminated, truncated, info = env.step(1 if obs[3] > 0 else 0)
    env.close()
    print("CartPole average steps:", np.mean([cartpole() for i in range(100)]))
    print("MountainCar average steps:", np.mean([car() for i in range(100)]))
    print("Taxi:", taxi(find_qvalues("Taxi-v3")))
