# policy_iteration.py
"""Sample for gymgrade: policy_iteration starts from a policy that alternates right and left. On the lab's
own example at discount 1 that start walks 0 -> 1 -> 0 at a cost of 1 a lap: it has no finite value, and the
lab's iterative evaluation never stops (`timeout`, named). Everywhere else it converges.
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
def value_iteration(P, nS, nA, beta=1, tol=1e-8, maxiter=3000):
    V = np.zeros(nS)
    for n in range(1, maxiter + 1):
        Q = np.array([[sum(p * (r + beta * V[s1]) for p, s1, r, _ in P[s][a]) for a in range(nA)] for s in range(nS)])
        V_new = Q.max(axis=1)
        if np.max(np.abs(V_new - V)) < tol:
            return V_new, n
        V = V_new
    return V, maxiter


# Problem 2
def policy_improvement(P, nS, nA, V, beta=1.0):
    Q = np.array([[sum(p * (r + beta * V[s1]) for p, s1, r, _ in P[s][a]) for a in range(nA)] for s in range(nS)])
    return np.argmax(Q, axis=1)


# Problem 3
def iter_policy_eval(P, nS, nA, policy, beta=1.0, tol=1e-8):
    V = np.zeros(nS)
    while True:
        V_new = np.array([sum(p * (r + beta * V[s1]) for p, s1, r, _ in P[s][policy[s]]) for s in range(nS)])
        if np.max(np.abs(V_new - V)) < tol:
            return V_new
        V = V_new


# Problem 4
def policy_iteration(P, nS, nA, beta=1, tol=1e-8, maxiter=200):
    policy = np.array([2 if s % 2 == 0 else 0 for s in range(nS)])  # right, left, right, left, ...
    for k in range(1, maxiter + 1):
        V = iter_policy_eval(P, nS, nA, policy, beta, tol)
        new_policy = policy_improvement(P, nS, nA, V, beta)
        if np.array_equal(new_policy, policy):
            return V, policy, k
        policy = new_policy
    return V, policy, maxiter
