# policy_iteration.py
"""Policy Function Iteration (2023, gym 0.26), answered as a student of that year wrote it.

Sample for gymgrade: gym 0.26's API (`obs, info = env.reset()`, five-value `step`), `P` read three wrappers
down (`gym.make(name).env.env.env.P`: TimeLimit > OrderEnforcing > PassiveEnvChecker > FrozenLakeEnv, each
forwarding attributes), the episodes played on `gym.make(name).env` (below the time limit, so they run to
their end), one loop playing one episode with each policy per pass.
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


# Problems 5 and 6
def frozen_lake(basic_case=True, M=1000, render=False):
    env_name = "FrozenLake-v1" if basic_case else "FrozenLake8x8-v1"
    made = gym.make(env_name, render_mode="human" if render else None)
    P = made.env.env.env.P
    env = made.env
    nS, nA = env.observation_space.n, env.action_space.n
    vi_value_func, _ = value_iteration(P, nS, nA)
    vi_policy = extract_policy(P, nS, nA, vi_value_func)
    pi_value_func, pi_policy, _ = policy_iteration(P, nS, nA)
    vi_total_rewards = 0
    pi_total_rewards = 0
    for _ in range(M):
        vi_total_rewards += run_simulation(env, vi_policy, render)
        pi_total_rewards += run_simulation(env, pi_policy, render)
    env.close()
    return vi_policy, vi_total_rewards / M, pi_value_func, pi_policy, pi_total_rewards / M


# Problem 6
def run_simulation(env, policy, render=True, beta=1.0):
    obs, info = env.reset()
    terminated = truncated = False
    total_reward, k = 0, 0
    while not (terminated or truncated):
        obs, reward, terminated, truncated, info = env.step(int(policy[obs]))
        total_reward += beta**k * reward
        k += 1
    return total_reward
