# policy_function_iteration.py
"""Sample for gymgrade: iter_policy_eval left as the template hands it out (NotImplementedError), while
policy_iteration, written as the text says, calls it. The missing step counts once, in its own problem:
policy_iteration is judged again with the grader's own iter_policy_eval in its place, and passes.
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


# Problem 2
def policy_improvement(P, nS, nA, V, beta=1.0):
    policy = np.zeros(nS, dtype=int)
    for s in range(nS):
        q = np.zeros(nA)
        for a in range(nA):
            for p, s_next, r, done in P[s][a]:
                q[a] += p * (r + beta * V[s_next])
        policy[s] = np.argmax(q)
    return policy


# Problem 3
def iter_policy_eval(P, nS, nA, policy, beta=1.0, tol=1e-8):
    raise NotImplementedError("Problem 3 Incomplete")


# Problem 4
def policy_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=200):
    pi = np.ones(nS, dtype=int)
    for n in range(1, maxiter + 1):
        V = iter_policy_eval(P, nS, nA, pi, beta, tol)
        pi_new = policy_improvement(P, nS, nA, V, beta)
        if np.linalg.norm(pi_new - pi) < tol:
            return V, pi_new, n
        pi = pi_new
    return V, pi, maxiter
