import sys

import gym


def random_blackjack(n):
    wins = 0
    for i in range(n):
        env = gym.make("Blackjack-v0")
        done = False
        while not done:
            obs, reward, done, info = env.step(env.action_space.sample())
        if reward == 1:
            wins += 1
        env.close()
    return wins / n


print(random_blackjack(int(sys.argv[1]) if len(sys.argv) > 1 else 500))
