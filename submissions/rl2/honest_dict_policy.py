# policy_iteration.py
"""Policy Function Iteration (2019-2022), answered as many students wrote it: policies kept as dicts.

Sample for gymgrade (honest): the policy is a dict {state: action} inside policy_iteration, passed to the
file's own compute_policy_v (which reads policy[s], right for a dict and for an array alike) and turned into
an array only when returned. Lists for the values, np.argmax over a list comprehension, a zero start. The
grader's own compute_policy_v, given that dict, could not read it: policy_iteration is judged with the file's
own steps first.
"""

import numpy as np
import gym

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
    V = [0.0] * nS
    for n in range(1, maxiter + 1):
        new_V = [max(sum(p * (r + beta * V[s_]) for p, s_, r, _ in P[s][a]) for a in range(nA)) for s in range(nS)]
        if np.linalg.norm(np.array(new_V) - np.array(V)) < tol:
            return np.array(new_V), n
        V = new_V
    return np.array(V), maxiter


# Problem 2
def extract_policy(P, nS, nA, v, beta=1.0):
    policy = {}
    for s in range(nS):
        policy[s] = int(np.argmax([sum(p * (r + beta * v[s_]) for p, s_, r, _ in P[s][a]) for a in range(nA)]))
    return np.array([policy[s] for s in range(nS)])


# Problem 3
def compute_policy_v(P, nS, nA, policy, beta=1.0, tol=1e-8):
    v = [0.0] * nS
    while True:
        new_v = [sum(p * (r + beta * v[s_]) for p, s_, r, _ in P[s][int(policy[s])]) for s in range(nS)]
        if np.linalg.norm(np.array(new_v) - np.array(v)) < tol:
            return np.array(new_v)
        v = new_v


# Problem 4
def policy_iteration(P, nS, nA, beta=1, tol=1e-8, maxiter=200):
    policy = {s: 0 for s in range(nS)}
    for k in range(1, maxiter + 1):
        v = compute_policy_v(P, nS, nA, policy, beta, tol)
        new_policy = {}
        for s in range(nS):
            new_policy[s] = int(np.argmax([sum(p * (r + beta * v[s_]) for p, s_, r, _ in P[s][a]) for a in range(nA)]))
        if new_policy == policy:
            break
        policy = new_policy
    return v, np.array([policy[s] for s in range(nS)]), k
