# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). Returns epsilon_end at the last episode."""


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    if episode == N:
        return epsilon_end
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta
