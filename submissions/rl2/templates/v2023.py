"""The v2023 template of the second lab (gymnasium (2023)), restated by gymgrade: every problem is a stub.

Sample for gymgrade: handed in unmodified, every problem is `missing`.
"""

import numpy as np
import gymnasium as gym

# The lab's example: Left 0, Down 1, Right 2, Up 3 on a 2x2 grid; state 3 ends the episode.
P = {s: {a: [] for a in range(4)} for s in range(4)}
P[0][0] = [(0, 0, 0, False)]
P[0][1] = [(1, 2, -1, False)]
P[0][2] = [(1, 1, 0, False)]
P[0][3] = [(0, 0, 0, False)]
P[1][0] = [(1, 0, -1, False)]
P[1][1] = [(1, 3, 1, True)]
P[1][2] = [(0, 0, 0, False)]
P[1][3] = [(0, 0, 0, False)]
P[2][0] = [(0, 2, -1, False)]
P[2][1] = [(0, 2, -1, False)]
P[2][2] = [(1, 3, 1, True)]
P[2][3] = [(1, 0, 0, False)]
P[3][0] = [(0, 0, 0, True)]
P[3][1] = [(0, 0, 0, True)]
P[3][2] = [(0, 0, 0, True)]
P[3][3] = [(0, 0, 1, True)]



# Problem 1
def value_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=3000):
    """Value iteration: return (V, n)."""
    raise NotImplementedError("Problem 1 Incomplete")


# Problem 2
def extract_policy(P, nS, nA, v, beta=1.0):
    """The greedy policy for the values v."""
    raise NotImplementedError("Problem 2 Incomplete")


# Problem 3
def compute_policy_v(P, nS, nA, policy, beta=1.0, tol=1e-8):
    """The policy's values, by iterative evaluation."""
    raise NotImplementedError("Problem 3 Incomplete")


# Problem 4
def policy_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=200):
    """Policy iteration: return (V, policy, n)."""
    raise NotImplementedError("Problem 4 Incomplete")


# Problem 5
def frozen_lake(basic_case=True, M=1000, render=False):
    """Solve FrozenLake both ways and play each policy M times (five results)."""
    raise NotImplementedError("Problem 5 Incomplete")


# Problem 6
def run_simulation(env, policy, beta=1.0):
    """One episode's discounted return."""
    raise NotImplementedError("Problem 6 Incomplete")
