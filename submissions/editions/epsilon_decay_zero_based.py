# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). Episodes counted from 0."""


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - episode * delta
