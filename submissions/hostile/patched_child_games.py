"""Hostile: rigs the game classes the sandbox child deals (whatever `type(env.unwrapped)` is, gymnasium's
class or the child's cheaper copy of it) and the deck module, so that every Blackjack game is a win and
every Taxi step pays 20."""

import gymnasium
from gymnasium.envs.toy_text import blackjack as blackjack_module


def _always_win(self, action):
    observation, reward, terminated, truncated, info = blackjack_module.BlackjackEnv.step(self, action)
    return observation, 1.0, True, truncated, info


def blackjack_wins(games):
    env = gymnasium.make("Blackjack-v1")
    type(env.unwrapped).step = _always_win
    blackjack_module.deck[:] = [10] * 13  # a deck of tens, for gymnasium's own draws
    wins = 0
    for _ in range(games):
        env.reset()
        _, reward, _, _, _ = env.step(0)
        wins += reward > 0
    return wins


def taxi_reward(steps):
    env = gymnasium.make("Taxi-v3")
    kind = type(env.unwrapped)
    real_step = kind.step

    def always_paid(self, action):
        observation, reward, terminated, truncated, info = real_step(self, action)
        return observation, 20, terminated, truncated, info

    kind.step = always_paid
    env.reset()
    total = 0
    for _ in range(steps):
        _, reward, terminated, truncated, _ = env.step(0)
        total += reward
        if terminated or truncated:
            env.reset()
    return total


def ok():
    return 42
