# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). So that the last episode reaches epsilon_end."""
import numpy as np


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    # np.linspace(start, end, N)[episode - 1]
    schedule = np.linspace(epsilon_start, epsilon_end, N)
    return schedule[episode - 1]
