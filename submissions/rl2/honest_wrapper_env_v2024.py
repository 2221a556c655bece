# policy_iteration.py
"""Reinforcement Learning 2 (2024, gymnasium 0.29), answered as a student of that year wrote it.

Sample for gymgrade: `env = gym.make(...).env` and `env.P` read on it, as gymnasium 0.29 allowed (its
`gym.make(...).env` is the OrderEnforcing wrapper below the time limit, which forwarded `P` with a
deprecation warning; gymnasium 1.x forwards nothing), the episodes played on that env (no time limit,
so they run to their end), one loop playing one episode with each policy per pass.
"""

import numpy as np
import gymnasium as gym
import model_free_RL  # For problem 7

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
def policy_improvement(P, nS, nA, V, beta=1.0):
    policy = np.zeros(nS, dtype=int)
    for s in range(nS):
        state_action_vector = np.zeros(nA)
        for a in range(nA):
            for p, next_s, r, _ in P[s][a]:
                state_action_vector[a] += p * (r + beta * V[next_s])
        policy[s] = np.argmax(state_action_vector)
    return policy


# Problem 3
def iter_policy_eval(P, nS, nA, policy, beta=1.0, tol=1e-8):
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
        V = iter_policy_eval(P, nS, nA, policy, beta, tol)
        new_policy = policy_improvement(P, nS, nA, V, beta)
        if np.linalg.norm(new_policy - policy) < tol:
            return V, new_policy, k
        policy = new_policy
    return V, policy, maxiter


# Problem 5
def run_simulation(env, policy, beta=1.0):
    observation, info = env.reset()
    terminated = truncated = False
    total, k = 0.0, 0
    while not (terminated or truncated):
        observation, reward, terminated, truncated, info = env.step(int(policy[observation]))
        total += beta**k * reward
        k += 1
    return total


# Problem 6
def frozen_lake(basic_case=True, M=1000, render=False):
    map_name = "4x4" if basic_case else "8x8"
    env = gym.make("FrozenLake-v1", map_name=map_name, is_slippery=True).env
    nS, nA = env.observation_space.n, env.action_space.n
    P = env.P
    vi_value_func, _ = value_iteration(P, nS, nA)
    vi_policy = policy_improvement(P, nS, nA, vi_value_func)
    pi_value_func, pi_policy, _ = policy_iteration(P, nS, nA)
    vi_total, pi_total = 0.0, 0.0
    for _ in range(M):
        vi_total += run_simulation(env, vi_policy)
        pi_total += run_simulation(env, pi_policy)
    env.close()
    return vi_value_func, vi_policy, vi_total / M, pi_value_func, pi_policy, pi_total / M


# Problem 7
def model_comparison(episodes=1000):
    model_free_RL.run_qlearn("FrozenLake-v1", decay=True, decay_type="linear")
    env = gym.make("FrozenLake-v1", desc=None, map_name="8x8", is_slippery=True)
    nS, nA = env.observation_space.n, env.action_space.n
    V, _ = value_iteration(env.unwrapped.P, nS, nA)
    policy = policy_improvement(env.unwrapped.P, nS, nA, V)
    avg_Q_reward = np.mean([model_free_RL.run_simulation_table(env, beta=1.0) for _ in range(episodes)])
    avg_val_iter_reward = np.mean([run_simulation(env, policy, beta=1.0) for _ in range(episodes)])
    env.close()
    statement = ("Value iteration uses the transition probabilities, so its policy is optimal for the lake. "
                 "Q-learning learns only from sampled episodes and gets a worse policy in the same time. "
                 "A model-free method needs no model but more experience.")
    return avg_Q_reward, avg_val_iter_reward, statement
