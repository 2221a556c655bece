"""The evaluation step's check (compute_policy_v to 2023, iter_policy_eval since 2024): one array, the
policy's exact value within the tolerance tol earns; a tuple and each typical mistake named."""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np
import pytest

from grader.lab.rl2.checks.evaluation import points
from grader.lab.rl2.checks.mdp_calls import cases
from reference.errors import UnboundedValueError
from reference.oracles.mdp import mdp_from_table, policy_value
from reference.rl2 import solutions
from tests.grader.lab.rl2.support import SEED, judged, read_outcomes


def evaluation(
    P: Any,
    nS: int,
    nA: int,
    policy: Any,
    beta: float = 1.0,
    tol: float = 1e-8,
    *,
    read: str = "all",
    discount: bool = True,
    start: float = 0.0,
    in_place: bool = False,
    with_count: bool = False,
    maxiter: int = 5000,
) -> Any:
    """The lab's iterative evaluation (2-norm stop), and each typical mistake as a switch.

    Each state's value adds `p * (r + beta * V[s'])` over its move's outcomes in their order, as the lab's
    loop over `P[s][policy[s]]` does (on Python floats: the same sums as on numpy's). At discount 1 a policy
    may have no value, and its evaluation would never stop (the sandbox's time limit would end it): it stops
    after `maxiter` sweeps instead (at SEED those that stop take at most 1 191).
    """
    factor = beta if discount else 1.0
    moves = [read_outcomes(P[s][int(policy[s])], read) for s in range(nS)]
    V = np.full(nS, start)
    for n in range(1, maxiter + 1):
        old = V.tolist()
        new = old.copy() if in_place else [0.0] * nS
        for s in range(nS):
            total = 0.0
            for p, s1, r, _ in moves[s]:
                total = total + p * (r + factor * (new if in_place else old)[s1])
            new[s] = total
        change = np.linalg.norm(np.array(new) - V)
        V = np.array(new)
        if change < tol:
            return (V, n) if with_count else V
    return (V, maxiter) if with_count else V


def test_the_policies_asked_have_finite_values_and_include_the_labs_start() -> None:
    asked = points(SEED)
    kinds = [point.kind for point in asked]
    assert kinds.count("the all-ones policy") == len(cases(SEED)) == 12
    assert all(bool(np.all(np.isfinite(point.exact))) for point in asked)
    held_out = [point for point in asked if point.case.key.startswith("random")]
    assert len(held_out) == 9  # below discount 1 every policy has a value: all three asked


@pytest.mark.parametrize(
    "function", [solutions.iter_policy_eval, evaluation, partial(evaluation, in_place=True)]
)
def test_the_reference_and_an_in_place_evaluation_pass(function: Any) -> None:
    verdict = judged("v2024", "iter_policy_eval", function)
    assert verdict.status == "passed", verdict.feedback


def test_the_2018_name_is_graded_the_same() -> None:
    assert judged("v2018", "compute_policy_v", solutions.iter_policy_eval).status == "passed"


def test_a_tuple_where_one_array_is_asked_for_is_named() -> None:
    verdict = judged("v2024", "iter_policy_eval", partial(evaluation, with_count=True))
    assert verdict.status == "failed"
    assert "returned a tuple where one array is asked for (36 of 36 calls)" in verdict.feedback


@pytest.mark.parametrize(
    ("changes", "cause"),
    [
        ({"discount": False}, "beta ignored"),
        ({"read": "first"}, "first outcome only"),
        ({"read": "last"}, "`=` where `+=` is meant"),
        ({"start": 1.0}, "values initialised to ones"),
    ],
    ids=["beta-ignored", "first-outcome", "assigns", "ones"],
)
def test_each_typical_mistake_is_named(changes: dict[str, Any], cause: str) -> None:
    verdict = judged("v2024", "iter_policy_eval", partial(evaluation, **changes))
    assert verdict.status == "failed" and f"Likely cause: {cause}" in verdict.feedback, verdict.feedback


@pytest.mark.parametrize(
    ("function", "found"),
    [
        (lambda *args: evaluation(*args) + 0.01, "its exact value on"),
        (lambda *args: np.array([1.0, 1.0, 1.0, 0.0]), "expected one array of the 16 values"),
        (lambda *args: "values", "returned a str; expected one array"),
    ],
    ids=["off-by-a-constant", "the-examples-answer", "text"],
)
def test_a_wrong_value_fails_without_a_cause(function: Any, found: str) -> None:
    verdict = judged("v2024", "iter_policy_eval", function)
    assert verdict.status == "failed" and found in verdict.feedback, verdict.feedback
    assert "Likely cause" not in verdict.feedback


def test_a_mistake_that_gives_no_value_for_any_wrong_call_is_not_named() -> None:
    """Wrong only where the policy has no value at discount 1: "beta ignored" gives no value there, so it
    explains none of the wrong calls, and no cause is named. Every MDP of the grader's make lets every policy
    end, so only the lab's example has such a policy: seed 38 asks it at 0.9 with the random policy
    right-then-left (0 -> 1 -> 0 at a cost), which has a value at 0.9 and none at 1."""

    def wrong_where_discount_1_has_no_value(
        P: Any, nS: int, nA: int, policy: Any, beta: float = 1.0, tol: float = 1e-8
    ) -> Any:
        values = solutions.iter_policy_eval(P, nS, nA, policy, beta, tol)
        try:
            policy_value(mdp_from_table("P", P, nS, nA), policy, 1.0)
        except UnboundedValueError:
            return values + 0.01
        return values

    verdict = judged("v2024", "iter_policy_eval", wrong_where_discount_1_has_no_value, seed=38)
    assert verdict.status == "failed" and "its exact value on" in verdict.feedback, verdict.feedback
    assert "Likely cause" not in verdict.feedback


def test_a_wrong_answer_names_the_kind_of_policy_it_was_asked_about() -> None:
    """The first call of each MDP asks about an optimal policy, read again from the call by the judge."""
    verdict = judged("v2024", "iter_policy_eval", lambda *args: evaluation(*args) + 0.01)
    assert verdict.status == "failed" and "(an optimal policy) returned" in verdict.feedback, verdict.feedback
