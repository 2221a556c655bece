"""Judge one sample of the second lab against the exact oracles, in a child run through `grader.compat`.

Used by test_rl2_samples.py only: `python -m grader.compat sample_judge.py SAMPLE EDITION PROBLEM...`
prints one JSON object, problem id -> status ("passed", "failed", "missing", "error", "timeout"). A test
double of the grader's checks for the pure problems and run_simulation: it proves that the MDPs the
grader owns and the oracles tell every sample apart, not how the grader words its feedback.
"""

from __future__ import annotations

import importlib.util
import json
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from reference.errors import UnboundedValueError
from reference.oracles.mdp import (
    greedy_gaps,
    lab_value_iteration,
    optimal_solution,
    policy_value,
    return_moments,
)
from reference.oracles.mdps import TIME_LIMITS, frozen_lake, grading_cases
from reference.rl2 import solutions

SECONDS_PER_PROBLEM = 20
VALUE_TOLERANCE = 1e-6
"""Values are asked at tol=1e-10; the lab's algorithm then lands within 1e-8 of the exact values."""
Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7: the false-fail probability of the slippery run_simulation mean."""
CLASSIC_EDITIONS = ("v2018", "v2019")
OLD_NAMES = ("v2018", "v2019", "v2023")
"""Editions whose evaluation and improvement steps are `compute_policy_v` and `extract_policy`."""
SEED = 20261128
"""The grading seed whose held-out random MDPs join the public cases (as the grader's checks add them)."""


class Timeout(Exception):
    pass


def _alarm(signum: int, frame: object) -> None:
    raise Timeout


def value_iteration(function: Callable[..., Any]) -> bool:
    example = grading_cases()[0]
    _, sweeps = function(example.mdp.as_dict(), 4, 4)
    if sweeps != lab_value_iteration(example.mdp, 1.0)[1]:
        return False
    for case in grading_cases(SEED):
        values, _ = function(
            case.mdp.as_dict(), case.mdp.n_states, case.mdp.n_actions, case.beta, 1e-10, 100_000
        )
        optimum = optimal_solution(case.mdp, case.beta).values
        if (
            np.shape(values) != optimum.shape
            or np.max(np.abs(np.asarray(values) - optimum)) > VALUE_TOLERANCE
        ):
            return False
    return True


def improvement(function: Callable[..., Any]) -> bool:
    for case in grading_cases(SEED):
        choice = np.random.default_rng(sum(map(ord, case.key)))
        for values in (
            optimal_solution(case.mdp, case.beta).values,
            choice.uniform(-1, 1, case.mdp.n_states),
        ):
            policy = function(
                case.mdp.as_dict(), case.mdp.n_states, case.mdp.n_actions, values.copy(), case.beta
            )
            if np.shape(policy) != (case.mdp.n_states,):
                return False
            if np.any(greedy_gaps(case.mdp, values, policy, case.beta) > 1e-9 * (1 + np.abs(values))):
                return False
    return True


def evaluation(function: Callable[..., Any]) -> bool:
    for case in grading_cases(SEED):
        policies = [optimal_solution(case.mdp, case.beta).policy, np.ones(case.mdp.n_states, dtype=int)]
        for policy in policies:
            try:
                exact = policy_value(case.mdp, policy, case.beta)
            except UnboundedValueError:
                continue
            values = function(
                case.mdp.as_dict(), case.mdp.n_states, case.mdp.n_actions, policy.copy(), case.beta, 1e-10
            )
            if not isinstance(values, np.ndarray) or values.shape != exact.shape:
                return False
            if np.max(np.abs(values - exact)) > VALUE_TOLERANCE:
                return False
    return True


def policy_iteration_either_reading(function: Callable[..., Any], edition: str) -> bool:
    """The student's own steps first; where that fails, the reference's steps bound in their place (the
    grader's second reading: a mistake in those steps counts in their own problems, and only ever helps)."""
    try:
        if policy_iteration(function):
            return True
    except Timeout:  # the start never converges: the grader's steps would loop as long
        raise
    except Exception:
        pass
    names = (
        ("compute_policy_v", "extract_policy")
        if edition in OLD_NAMES
        else ("iter_policy_eval", "policy_improvement")
    )
    module = function.__globals__
    kept = {name: module.get(name) for name in names}
    module.update(zip(names, (solutions.iter_policy_eval, solutions.policy_improvement), strict=True))
    try:
        return policy_iteration(function)
    finally:
        module.update(kept)


def policy_iteration(function: Callable[..., Any]) -> bool:
    for case in grading_cases(SEED):
        values, policy, _ = function(
            case.mdp.as_dict(), case.mdp.n_states, case.mdp.n_actions, case.beta, 1e-10
        )
        optimum = optimal_solution(case.mdp, case.beta).values
        if (
            np.shape(values) != optimum.shape
            or np.max(np.abs(np.asarray(values) - optimum)) > VALUE_TOLERANCE
        ):
            return False
        if np.shape(policy) != optimum.shape:
            return False
        if np.any(optimum - policy_value(case.mdp, policy, case.beta) > 1e-9):
            return False
    return True


def run_simulation(function: Callable[..., Any], edition: str) -> bool:
    def make(slippery: bool) -> Any:
        if edition in CLASSIC_EDITIONS:
            import gym  # the compat layer's classic gym

            return gym.make("FrozenLake-v1", is_slippery=slippery)
        return gymnasium.make("FrozenLake-v1", is_slippery=slippery)

    still = frozen_lake("4x4", slippery=False)
    env = make(False)
    for beta in (1.0, 0.9, 0.5):
        plan = optimal_solution(still, min(beta, 0.9)).policy
        if abs(float(function(env, plan, beta=beta)) - beta**5) > 1e-12:  # six steps: the reward at k = 5
            return False
    env.close()
    lake = frozen_lake("4x4", slippery=True)
    policy = optimal_solution(lake, 1.0).policy
    moments = return_moments(lake, policy, 0.9, steps=TIME_LIMITS["FrozenLake-v1"])
    env = make(True)
    env.reset(seed=12345)
    episodes = 2_000
    returns = np.array([float(function(env, policy, beta=0.9)) for _ in range(episodes)])
    env.close()
    return bool(abs(returns.mean() - moments.mean[0]) <= Z_LIMIT * np.sqrt(moments.variance[0] / episodes))


JUDGES: dict[str, Callable[[Callable[..., Any], str], bool]] = {
    "value_iteration": lambda function, _: value_iteration(function),
    "extract_policy": lambda function, _: improvement(function),
    "policy_improvement": lambda function, _: improvement(function),
    "compute_policy_v": lambda function, _: evaluation(function),
    "iter_policy_eval": lambda function, _: evaluation(function),
    "policy_iteration": policy_iteration_either_reading,
    "run_simulation": run_simulation,
}


def main() -> None:
    sample, edition, problems = Path(sys.argv[1]), sys.argv[2], sys.argv[3:]
    spec = importlib.util.spec_from_file_location("submission", sample)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    signal.signal(signal.SIGALRM, _alarm)
    statuses = {}
    for problem in problems:
        signal.alarm(SECONDS_PER_PROBLEM)
        try:
            statuses[problem] = "passed" if JUDGES[problem](getattr(module, problem), edition) else "failed"
        except NotImplementedError:
            statuses[problem] = "missing"
        except Timeout:
            statuses[problem] = "timeout"
        except Exception as error:
            statuses[problem] = f"error: {type(error).__name__}: {error}"
        finally:
            signal.alarm(0)
    print(json.dumps(statuses))


main()
