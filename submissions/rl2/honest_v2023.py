# policy_iteration.py
"""Policy Function Iteration (2023, gymnasium), answered as a student following the template would.

Sample for gymgrade: an honest file of the 2023 edition: `extract_policy`, `compute_policy_v`, five results,
and `env.P` read straight from `gym.make`'s env, as the text does (gymnasium 1.x needs the grader's help).
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
    V_old = np.zeros(nS)
    for n in range(1, maxiter + 1):
        V_new = np.zeros(nS)
        for s in range(nS):
            state_action_vector = np.zeros(nA)
            for a in range(nA):
                for p, next_s, r, _ in P[s][a]:
                    state_action_vector[a] += p * (r + beta * V_old[next_s])
            V_new[s] = state_action_vector.max()
        if np.linalg.norm(V_new - V_old) < tol:
            return V_new, n
        V_old = V_new
    return V_old, maxiter


# Problem 2
def extract_policy(P, nS, nA, v, beta=1.0):
    policy = np.zeros(nS, dtype=int)
    for s in range(nS):
        state_action_vector = np.zeros(nA)
        for a in range(nA):
            for p, next_s, r, _ in P[s][a]:
                state_action_vector[a] += p * (r + beta * v[next_s])
        policy[s] = np.argmax(state_action_vector)
    return policy


# Problem 3
def compute_policy_v(P, nS, nA, policy, beta=1.0, tol=1e-8):
    V_old = np.zeros(nS)
    while True:
        V_new = np.zeros(nS)
        for s in range(nS):
            for p, next_s, r, _ in P[s][int(policy[s])]:
                V_new[s] += p * (r + beta * V_old[next_s])
        if np.linalg.norm(V_new - V_old) < tol:
            return V_new
        V_old = V_new


# Problem 4
def policy_iteration(P, nS, nA, beta=1.0, tol=1e-8, maxiter=200):
    policy = np.ones(nS, dtype=int)
    for k in range(1, maxiter + 1):
        V = compute_policy_v(P, nS, nA, policy, beta, tol)
        new_policy = extract_policy(P, nS, nA, V, beta)
        if np.linalg.norm(new_policy - policy) < tol:
            return V, new_policy, k
        policy = new_policy
    return V, policy, maxiter


# Problem 6
def run_simulation(env, policy, beta=1.0):
    observation, info = env.reset()
    done = False
    total, k = 0.0, 0
    while not done:
        observation, reward, done, truncated, info = env.step(int(policy[observation]))
        total += beta**k * reward
        k += 1
    return total


# Problems 5 and 6
def frozen_lake(basic_case=True, M=1000, render=False):
    env_name = "4x4" if basic_case else "8x8"
    env = gym.make("FrozenLake-v1", map_name=env_name, is_slippery=True)
    nS, nA = env.observation_space.n, env.action_space.n
    vi_value, _ = value_iteration(env.P, nS, nA)
    vi_policy = extract_policy(env.P, nS, nA, vi_value)
    pi_value_func, pi_policy, _ = policy_iteration(env.P, nS, nA)
    vi_total_rewards = np.mean([run_simulation(env, vi_policy) for _ in range(M)])
    pi_total_rewards = np.mean([run_simulation(env, pi_policy) for _ in range(M)])
    env.close()
    return vi_policy, vi_total_rewards, pi_value_func, pi_policy, pi_total_rewards
