# policy_iteration.py
"""Sample for gymgrade: compute_policy_v returns (V, n), the values and the sweeps it took, where the lab
asks for one array; the file's policy_iteration unpacks it (`V, n = compute_policy_v(...)`), right for that
evaluation. The mistake counts once: compute_policy_v fails, policy_iteration (judged with the file's own
steps first) passes. Lists as policies, an all-ones start as the 2023 text writes it.
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
    V_old = np.zeros(nS)
    for i in range(maxiter):
        V_new = np.zeros(nS)
        for s in range(nS):
            sa = np.zeros(nA)
            for a in range(nA):
                for tuple_info in P[s][a]:
                    p, next_s, r, _ = tuple_info
                    sa[a] += p * (r + beta * V_old[next_s])
            V_new[s] = sa.max()
        if np.linalg.norm(V_new - V_old) < tol:
            return V_new, i + 1
        V_old = V_new.copy()
    return V_new, maxiter


# Problem 2
def extract_policy(P, nS, nA, v, beta=1.0):
    policy = []
    for s in range(nS):
        sa = np.zeros(nA)
        for a in range(nA):
            for p, next_s, r, _ in P[s][a]:
                sa[a] += p * (r + beta * v[next_s])
        policy.append(int(np.argmax(sa)))
    return np.array(policy)


# Problem 3
def compute_policy_v(P, nS, nA, policy, beta=1.0, tol=1e-8):
    V = np.zeros(nS)
    n = 0
    while True:
        n += 1
        V_new = np.zeros(nS)
        for s in range(nS):
            for p, next_s, r, _ in P[s][policy[s]]:
                V_new[s] += p * (r + beta * V[next_s])
        if np.max(np.abs(V_new - V)) < tol:
            return V_new, n
        V = V_new


# Problem 4
def policy_iteration(P, nS, nA, beta=1, tol=1e-8, maxiter=200):
    policy = [1] * nS
    for k in range(1, maxiter + 1):
        V, n = compute_policy_v(P, nS, nA, policy, beta, tol)
        new_policy = list(extract_policy(P, nS, nA, V, beta))
        if np.linalg.norm(np.array(new_policy) - np.array(policy)) < tol:
            return V, np.array(new_policy), k
        policy = new_policy
    return V, np.array(policy), maxiter
