"""policy_iteration's check: the policy judged by its exact value, V against the optimum, n a whole number of
iterations; a start that never converges at discount 1 is a named timeout; the feedback says whose
evaluation and improvement steps the calls used."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from grader.lab.rl2.checks.mdp_calls import cases
from grader.sandbox.outcome import OutcomeStatus
from reference.oracles.mdp import optimal_solution
from reference.rl2 import solutions
from tests.grader.lab.rl2.support import SEED, judged, judged_outcomes, outcome, settings, wire

RING = next(index for index, case in enumerate(cases(SEED)) if case.key == "ring")
RING_DISCOUNTED = next(index for index, case in enumerate(cases(SEED)) if case.key == "ring_0.8")


def test_the_reference_passes_and_the_feedback_names_the_graders_helpers() -> None:
    verdict = judged("v2024", "policy_iteration", solutions.policy_iteration)
    assert verdict.status == "passed", verdict.feedback
    reading = "policy_iteration was called with the grader's own iter_policy_eval and policy_improvement (the lab's algorithms) in place of yours, so a mistake in those counts only in their own problems."  # noqa: E501
    assert reading in verdict.feedback
    plan = [call.provided for call in _plan("v2018")]
    assert set(plan) == {("compute_policy_v", "extract_policy")}


def test_with_the_students_helpers_no_name_is_bound_and_the_feedback_says_so() -> None:
    assert {call.provided for call in _plan("v2024", helpers="student")} == {()}
    # judged here, no name is bound either way: any passing function shows the feedback's reading
    verdict = judged("v2024", "policy_iteration", _optimal, helpers="student")
    assert verdict.status == "passed", verdict.feedback
    assert "called with your own iter_policy_eval and policy_improvement" in verdict.feedback


def _plan(edition: str, **changes: Any) -> list[Any]:
    from grader.lab.editions import edition_of

    return (
        edition_of(edition)
        .registry.problem("policy_iteration")
        .check.plan(settings(edition, "policy_iteration", **changes), {}, SEED)
    )


def _optimal(P: Any, nS: int, nA: int, beta: float = 1.0, *rest: Any) -> Any:
    case = next(
        case
        for case in cases(SEED)
        if case.mdp.n_states == nS and case.beta == beta and case.mdp.as_dict() == P
    )
    solved = optimal_solution(case.mdp, beta)
    return solved.values, solved.policy, 2


@pytest.mark.parametrize(
    ("function", "found"),
    [
        (lambda *a: (_optimal(*a)[0], np.ones(a[1], dtype=int), 1), "which is not optimal on"),
        (lambda *a: (np.zeros(a[1]), _optimal(*a)[1], 2), "returned an optimal policy but V ="),
        (
            lambda *a: (*_optimal(*a)[:2], 0),
            "returned n = 0; expected the number of iterations made, 1 to maxiter = 200",
        ),
        (lambda *a: _optimal(*a)[:2], "expected (V, policy, n)"),
        (lambda *a: (np.array([1.0, 1.0, 1.0, 0.0]), np.array([2, 1, 2, 0]), 3), "but V = [1, 1, 1, 0]"),
    ],
    ids=["not-optimal", "wrong-values", "n-zero", "no-n", "the-examples-answer"],
)
def test_each_wrong_answer_fails_with_what_was_wrong(function: Any, found: str) -> None:
    verdict = judged("v2024", "policy_iteration", function)
    assert verdict.status == "failed" and found in verdict.feedback, verdict.feedback


def test_another_optimal_policy_among_ties_passes() -> None:
    verdict = judged("v2024", "policy_iteration", _optimal)
    assert verdict.status == "passed", verdict.feedback


def _timing_out(index: int) -> Any:
    """Outcomes in plan order (one call per case): the call at `index` timed out, the others optimal."""
    made = iter(range(len(cases(SEED))))

    def outcomes(call: Any) -> Any:
        position = next(made)
        if position == index:
            return outcome(
                call,
                status=OutcomeStatus.TIMEOUT,
                message="policy_iteration() did not return within 20 seconds",
            )
        solved = optimal_solution(cases(SEED)[position].mdp, cases(SEED)[position].beta)
        return outcome(call, wire((solved.values, solved.policy, 3)))

    return outcomes


def test_a_start_that_never_converges_at_discount_1_is_a_named_timeout() -> None:
    verdict = judged_outcomes("v2024", "policy_iteration", _timing_out(RING))
    assert verdict.status == "timeout"
    assert "did not return within 20 seconds" in verdict.feedback
    assert "your start policy never converges at discount 1" in verdict.feedback
    assert "np.ones(nS, dtype=int)" in verdict.feedback


def test_a_timeout_below_discount_1_is_not_blamed_on_the_start() -> None:
    verdict = judged_outcomes("v2024", "policy_iteration", _timing_out(RING_DISCOUNTED))
    assert verdict.status == "timeout"
    assert "never converges" not in verdict.feedback


@pytest.mark.parametrize(
    ("name", "keyword"),
    [("extract_policy", "v"), ("policy_improvement", "V")],
)
def test_the_graders_improvement_step_takes_its_editions_parameter_names(name: str, keyword: str) -> None:
    from grader.sandbox.child.provided import PROVIDED

    example = cases(SEED)[0].mdp
    policy = PROVIDED[name](example.as_dict(), 4, 4, **{keyword: np.array([1.0, 1.0, 1.0, 0.0])}, beta=1.0)
    assert policy.tolist() == [2, 1, 2, 0]  # the lab's stated policy (first best action)
    values = PROVIDED["compute_policy_v"](
        example.as_dict(), 4, 4, policy, 1.0, 1e-8, 3000
    )  # an extra maxiter
    assert values.tolist() == [1.0, 1.0, 1.0, 0.0]
