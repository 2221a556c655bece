# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). Decays towards 0, forgetting epsilon_end."""


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    return epsilon_start * (1 - (episode - 1) / N)
