# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). Honest: the decay applied episode by episode."""


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (epsilon_start - epsilon_end) / N
    epsilon = epsilon_start
    for _ in range(episode - 1):
        epsilon -= delta
    return epsilon
