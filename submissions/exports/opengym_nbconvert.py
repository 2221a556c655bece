#!/usr/bin/env python
# coding: utf-8

# # Volume 2: OpenGym AI
# A. Student, Math 321, September 2020

# In[2]:


get_ipython().system('pip install gym')


# In[3]:


get_ipython().run_line_magic('matplotlib', 'inline')
import gym
import numpy as np
from IPython.display import clear_output
import random
from matplotlib import pyplot as plt


# In[4]:


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
        state = env.reset()

        epochs, penalties, reward, = 0, 0, 0
        done = False

        while not done:
            # Accept based on alpha
            if random.uniform(0, 1) < epsilon:
                action = env.action_space.sample()
            else:
                action = np.argmax(q_table[state])

            # Take action
            next_state, reward, done, info = env.step(action)

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


# ## Problem 1

# In[6]:


def random_blackjack(n):
    """Play n games of Blackjack with random actions.

    Parameters:
        n (int): how many games to play

    Returns:
        (float): the fraction of the n games that the player won
    """
    env = gym.make("Blackjack-v0")
    wins = 0
    for i in range(n):
        env.reset()
        done = False
        while not done:
            # take random actions until the game is over
            observation, reward, done, info = env.step(env.action_space.sample())
        if reward == 1:
            wins += 1
    env.close()
    return wins / n

print(random_blackjack(500))


# ## Problem 2

# In[8]:


def blackjack(n=11):
    """Play 10000 games of Blackjack, drawing while the hand is at most n.

    Parameters:
        n (int): the largest hand on which the player still draws

    Returns:
        (float): the fraction of the 10000 games that the player won
    """
    env = gym.make("Blackjack-v0")
    wins = 0
    for i in range(10000):
        observation = env.reset()
        done = False
        while not done:
            # draw while the hand is at most n, otherwise stop
            if observation[0] <= n:
                observation, reward, done, info = env.step(1)
            else:
                observation, reward, done, info = env.step(0)
        if reward == 1:
            wins += 1
    env.close()
    return wins / 10000


# In[9]:


domain = np.arange(1, 22)
win_rates = [blackjack(n) for n in domain]
plt.plot(domain, win_rates)
plt.xlabel('n')
plt.ylabel('win rate')
plt.show()
print('Best n:', domain[np.argmax(win_rates)])


# ## Problem 3

# In[11]:


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


# In[12]:


env = gym.make('CartPole-v0')
try:
    obs = env.reset()
    done = False
    while not done:
        env.render()
        obs, reward, done, info = env.step(1 if obs[3] > 0 else 0)
finally:
    env.close()


# In[13]:


get_ipython().run_cell_magic('time', '', 'print(np.mean([cartpole() for i in range(100)]))\n')


# ## Problem 4

# In[15]:


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


# In[16]:


get_ipython().run_line_magic('timeit', 'car()')
np.mean([car() for i in range(100)])


# ## Problem 5

# In[18]:


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
        env.reset()
        done = False
        total_reward = 0
        while not done:
            state, reward, done, info = env.step(env.action_space.sample())
            total_reward += reward
        naive_rewards.append(total_reward)

    # actions from the Q-table
    q_rewards = []
    for i in range(10000):
        state = env.reset()
        done = False
        total_reward = 0
        while not done:
            action = np.argmax(q_table[state])
            state, reward, done, info = env.step(action)
            total_reward += reward
        q_rewards.append(total_reward)

    env.close()
    return np.mean(naive_rewards), np.mean(q_rewards)


# In[19]:


q_table = find_qvalues('Taxi-v3', alpha=.1, gamma=.6, epsilon=.1)
taxi(q_table)

