"""Tests for reference/rl2: the second lab's model answers, judged by the exact oracles, in every edition."""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from grader.compat import make as classic_make
from grader.compat import shim_paths
from reference.oracles.mdp import (
    greedy_gaps,
    judge_policy,
    lab_value_iteration,
    optimal_solution,
    policy_value,
    return_moments,
)
from reference.oracles.mdps import TIME_LIMITS, frozen_lake, grading_cases, lab_example
from reference.rl2 import solutions
from reference.rl2.editions import EDITIONS

CASES = grading_cases()
Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7 for one (asymptotically) normal statistic."""

SIGNATURES = {
    "v2018": {
        "value_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=3000)",
        "extract_policy": "(P, nS, nA, V, beta=1.0)",
        "compute_policy_v": "(P, nS, nA, policy, beta=1.0, tol=1e-08)",
        "policy_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=200)",
        "frozenlake": "(basic_case=True, M=1000)",
        "run_simulation": "(env, policy, beta=1.0)",
    },
    "v2019": {
        "value_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=3000)",
        "extract_policy": "(P, nS, nA, V, beta=1.0)",
        "compute_policy_v": "(P, nS, nA, policy, beta=1.0, tol=1e-08)",
        "policy_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=200)",
        "frozen_lake": "(basic_case=True, M=1000, render=False)",
        "run_simulation": "(env, policy, render=True, beta=1.0)",
    },
    "v2023": {
        "value_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=3000)",
        "extract_policy": "(P, nS, nA, V, beta=1.0)",
        "compute_policy_v": "(P, nS, nA, policy, beta=1.0, tol=1e-08)",
        "policy_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=200)",
        "frozen_lake": "(basic_case=True, M=1000, render=False)",
        "run_simulation": "(env, policy, beta=1.0)",
    },
    "v2024": {
        "value_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=3000)",
        "policy_improvement": "(P, nS, nA, V, beta=1.0)",
        "iter_policy_eval": "(P, nS, nA, policy, beta=1.0, tol=1e-08)",
        "policy_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=200)",
        "frozen_lake": "(basic_case=True, M=1000, render=False)",
        "run_simulation": "(env, policy, beta=1.0)",
        "model_comparison": "(episodes=1000, *, training_episodes=70000)",
    },
    "v2026": {
        "value_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=3000)",
        "policy_improvement": "(P, nS, nA, V, beta=1.0)",
        "iter_policy_eval": "(P, nS, nA, policy, beta=1.0, tol=1e-08)",
        "policy_iteration": "(P, nS, nA, beta=1.0, tol=1e-08, maxiter=200)",
        "frozen_lake": "(basic_case=True, M=1000, render=False)",
        "run_simulation": "(env, policy, beta=1.0)",
    },
}
"""Each edition's functions and parameters, as its lab text and template give them."""


def _plain(signature: inspect.Signature) -> str:
    return str(
        signature.replace(
            parameters=[p.replace(annotation=inspect.Parameter.empty) for p in signature.parameters.values()],
            return_annotation=inspect.Signature.empty,
        )
    )


@pytest.mark.parametrize("edition", EDITIONS)
def test_each_edition_defines_its_own_names_and_signatures(edition: str) -> None:
    module = importlib.import_module(f"reference.rl2.editions.{edition}")
    assert sorted(module.__all__) == sorted(SIGNATURES[edition])
    assert {name: _plain(inspect.signature(getattr(module, name))) for name in module.__all__} == SIGNATURES[
        edition
    ]


@pytest.mark.parametrize(
    "case",
    [
        pytest.param(case, id=case.key, marks=[pytest.mark.slow] if case.key == "lake8" else [])
        for case in CASES
    ],
)
def test_the_model_answers_pass_the_oracles(case) -> None:  # type: ignore[no-untyped-def]
    P, nS, nA = case.mdp.as_dict(), case.mdp.n_states, case.mdp.n_actions
    optimum = optimal_solution(case.mdp, case.beta).values
    values, sweeps = solutions.value_iteration(P, nS, nA, case.beta, tol=1e-12, maxiter=100_000)
    np.testing.assert_allclose(values, optimum, atol=1e-9)
    assert sweeps == lab_value_iteration(case.mdp, case.beta, tol=1e-12, maxiter=100_000)[1]
    policy = solutions.policy_improvement(P, nS, nA, optimum, case.beta)
    assert np.all(greedy_gaps(case.mdp, optimum, policy, case.beta) <= 1e-12)
    np.testing.assert_allclose(
        solutions.iter_policy_eval(P, nS, nA, policy, case.beta, tol=1e-12),
        policy_value(case.mdp, policy, case.beta),
        atol=1e-9,
    )
    pi_values, pi_policy, _ = solutions.policy_iteration(P, nS, nA, case.beta, tol=1e-12)
    assert judge_policy(case.mdp, pi_policy, case.beta).optimal
    np.testing.assert_allclose(pi_values, optimum, atol=1e-9)


def test_the_example_as_the_lab_states_it() -> None:
    example = lab_example()
    P = example.as_dict()
    values, sweeps = solutions.value_iteration(P, 4, 4)
    assert (values.tolist(), sweeps) == ([1, 1, 1, 0], 3)
    assert solutions.policy_improvement(P, 4, 4, values).tolist() == [2, 1, 2, 0]
    assert solutions.value_iteration(P, 4, 4, beta=0.9)[0].tolist() == pytest.approx(
        [0.9, 1, 1, 0], abs=1e-15
    )


@pytest.mark.parametrize("api", ["gymnasium", "classic"])
def test_run_simulation_sums_the_discounted_rewards_from_step_0(api: str) -> None:
    lake = frozen_lake("4x4", slippery=False)
    policy = optimal_solution(lake, 0.8).policy
    if api == "gymnasium":
        env = gym.make("FrozenLake-v1", is_slippery=False)
    else:
        env = classic_make("FrozenLake-v0", is_slippery=False)
    try:
        # Six steps to the goal: the reward 1 arrives at k = 5.
        assert solutions.run_simulation(env, policy, 0.8) == pytest.approx(0.8**5, rel=1e-15)
        assert solutions.run_simulation(env, policy) == 1.0
    finally:
        env.close()


@pytest.mark.slow
@pytest.mark.parametrize("edition", ["v2018", "v2019", "v2023", "v2024", "v2026"])
def test_frozen_lake_in_each_edition(edition: str) -> None:
    module = importlib.import_module(f"reference.rl2.editions.{edition}")
    play = module.frozenlake if edition == "v2018" else module.frozen_lake
    results = play(True, 400)
    lake = frozen_lake("4x4", slippery=True)
    if edition in ("v2024", "v2026"):
        vi_values, vi_policy, vi_mean, pi_values, pi_policy, pi_mean = results
        np.testing.assert_allclose(vi_values, optimal_solution(lake, 1.0).values, atol=1e-6)
    else:
        assert len(results) == 5
        vi_policy, vi_mean, pi_values, pi_policy, pi_mean = results
    assert judge_policy(lake, vi_policy, 1.0).optimal and judge_policy(lake, pi_policy, 1.0).optimal
    np.testing.assert_allclose(pi_values, optimal_solution(lake, 1.0).values, atol=1e-6)
    # Episodes without the time limit: mean 14/17, the variance of a Bernoulli(14/17) return.
    spread = np.sqrt(14 / 17 * 3 / 17 / 400)
    assert abs(vi_mean - 14 / 17) <= Z_LIMIT * spread and abs(pi_mean - 14 / 17) <= Z_LIMIT * spread


@pytest.mark.slow
def test_model_comparison_trains_in_the_working_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(shim_paths().first))  # model_free_RL, as the sandbox provides it
    monkeypatch.chdir(tmp_path)
    from reference.rl2.editions.v2024 import model_comparison

    q_mean, vi_mean, statement = model_comparison(200, training_episodes=2_000)
    assert (tmp_path / "q_table.npy").is_file()
    assert np.load(tmp_path / "q_table.npy").shape == (64, 4)
    # Judged against the exact mean of the policy it played (value iteration's first argmax) under the
    # 100-step limit of gym.make('FrozenLake-v1', map_name='8x8'): optimal policies differ in speed, and
    # the limit cuts slow ones.
    lake = frozen_lake("8x8", slippery=True)
    values, _ = solutions.value_iteration(lake.as_dict(), 64, 4)
    played = solutions.policy_improvement(lake.as_dict(), 64, 4, values)
    limited = return_moments(lake, played, 1.0, steps=TIME_LIMITS["FrozenLake-v1"])
    assert abs(vi_mean - limited.mean[0]) <= Z_LIMIT * np.sqrt(limited.variance[0] / 200)
    assert 0.0 <= q_mean <= 1.0 and 2 <= statement.count(". ") + 1 <= 4
