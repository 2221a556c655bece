# opengym.py
"""Volume 2: OpenGym AI.
Grace Okafor
Applied Math 2
Fall
"""

import gym
import numpy as np
from IPython.display import clear_output
import random

BLACKJACK_GAMES = 10000
TAXI_EPISODES = 10000
HIT, STICK = 1, 0


# Problem 1
def random_blackjack(n):
    """
    Play n games of blackjack with randomly choosen actions.

    Parameters:
        n (int): number of games

    Returns:
        (float): percent of games won, as a fraction
    """
    environment = gym.make("Blackjack-v0")
    number_won = 0
    game_number = 0
    while game_number < n:
        environment.reset()
        game_over = False
        final_reward = 0
        while game_over is False:
            random_action = environment.action_space.sample()
            new_state, final_reward, game_over, extra = environment.step(random_action)
        if final_reward == 1.0:
            number_won = number_won + 1
        game_number = game_number + 1
    environment.close()
    return number_won / n


# Problem 2
def blackjack(n=11):
    """
    Hit untill the hand is bigger than n, then stick.
    """
    environment = gym.make("Blackjack-v0")
    number_won = 0
    for game_number in range(BLACKJACK_GAMES):
        current_state = environment.reset()
        game_over = False
        while game_over is False:
            my_hand = current_state[0]
            if my_hand > n:
                chosen_action = STICK
            else:
                chosen_action = HIT
            current_state, final_reward, game_over, extra = environment.step(chosen_action)
        if final_reward == 1.0:
            number_won = number_won + 1
    environment.close()
    return number_won / BLACKJACK_GAMES


# Problem 3
def cartpole():
    """
    Keep the pole upright by pushing in the direction of the tips angular velocity.
    """
    environment = gym.make("CartPole-v0")
    current_state = environment.reset()
    time_steps = 0
    game_over = False
    while game_over is False:
        angular_velocity = current_state[3]
        if angular_velocity > 0:
            chosen_action = 1
        else:
            chosen_action = 0
        current_state, final_reward, game_over, extra = environment.step(chosen_action)
        time_steps = time_steps + 1
    environment.close()
    return time_steps


# Problem 4
def car():
    """
    Rock the car back and fourth to build up momentum.
    """
    environment = gym.make("MountainCar-v0")
    current_state = environment.reset()
    time_steps = 0
    game_over = False
    while game_over is False:
        car_velocity = current_state[1]
        if car_velocity < 0:
            chosen_action = 0
        else:
            chosen_action = 2
        current_state, final_reward, game_over, extra = environment.step(chosen_action)
        time_steps = time_steps + 1
    environment.close()
    return time_steps


# Problem 5
def taxi(q_table):
    """
    Compare random actions to the q table's actions.
    """
    environment = gym.make("Taxi-v3")
    random_rewards = []
    for episode_number in range(TAXI_EPISODES):
        environment.reset()
        game_over = False
        episode_reward = 0
        while game_over is False:
            current_state, step_reward, game_over, extra = environment.step(environment.action_space.sample())
            episode_reward = episode_reward + step_reward
        random_rewards.append(episode_reward)
    table_rewards = []
    for episode_number in range(TAXI_EPISODES):
        current_state = environment.reset()
        game_over = False
        episode_reward = 0
        while game_over is False:
            best_action = np.argmax(q_table[current_state])
            current_state, step_reward, game_over, extra = environment.step(best_action)
            episode_reward = episode_reward + step_reward
        table_rewards.append(episode_reward)
    environment.close()
    return np.mean(random_rewards), np.mean(table_rewards)
