# OpenGym -- Priya Raman
import gym
import numpy as np

MAX_STEPS = 1000


def run_episode(env, decide):
    """Plays until the game ends (or MAX_STEPS) and returns the list of rewards we recieve."""
    observation = env.reset()
    history = []
    for _ in range(MAX_STEPS):
        observation, reward, done, _ = env.step(decide(observation))
        history.append(reward)
        if done:
            break
    return history


def random_blackjack(n):
    env = gym.make("Blackjack-v0")
    # last reward of each game tells us who won
    finals = np.array([run_episode(env, lambda o: np.random.choice([0, 1]))[-1] for _ in range(n)])
    return np.mean(finals == 1)


def blackjack(n=11):
    env = gym.make("Blackjack-v0")
    finals = np.array([run_episode(env, lambda o: 1 if o[0] <= n else 0)[-1] for _ in range(10000)])
    return np.mean(finals == 1)


def cartpole():
    env = gym.make("CartPole-v0")
    # the episode length is the number of rewards
    return len(run_episode(env, lambda o: 1 if o[3] > 0 else 0))


def car():
    env = gym.make("MountainCar-v0")
    return len(run_episode(env, lambda o: 0 if o[1] < 0 else 2))


def taxi(q_table):
    env = gym.make("Taxi-v3")
    random_returns = [sum(run_episode(env, lambda o: env.action_space.sample())) for _ in range(10000)]
    greedy_returns = [sum(run_episode(env, lambda o: np.argmax(q_table[o]))) for _ in range(10000)]
    return np.mean(random_returns), np.mean(greedy_returns)
