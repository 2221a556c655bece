# policy_iteration.py
"""Policy Function Iteration (2021, gym 0.21), answered as a student of that year wrote it.

Sample for gymgrade: the classic API, `env = gym.make(name).env` (the env inside the time limit, so the
episodes run to their end) with `env.P` and `observation_space.n`, one loop playing one episode with each
policy per pass (`vi += run_simulation(env, vi_policy); pi += run_simulation(env, pi_policy)`).
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
    env = gym.make(env_name).env
    nS = env.observation_space.n
    nA = env.action_space.n
    P = env.P
    vi_value_func, _ = value_iteration(P, nS, nA)
    vi_policy = extract_policy(P, nS, nA, vi_value_func)
    pi_value_func, pi_policy, _ = policy_iteration(P, nS, nA)
    vi = 0
    pi = 0
    for _ in range(M):
        vi += run_simulation(env, vi_policy, render)
        pi += run_simulation(env, pi_policy, render)
    env.close()
    return vi_policy, vi / float(M), pi_value_func, pi_policy, pi / float(M)


# Problem 6
def run_simulation(env, policy, render=True, beta=1.0):
    obs = env.reset()
    total_reward = 0
    step_index = 0
    while True:
        if render:
            env.render(mode="human")
        obs, reward, done, _ = env.step(int(policy[obs]))
        total_reward += beta**step_index * reward
        step_index += 1
        if done:
            break
    return total_reward
