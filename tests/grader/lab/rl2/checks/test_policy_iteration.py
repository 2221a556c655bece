"""policy_iteration's check: the policy judged by its exact value, V against the optimum, n a whole number of
iterations; a start that never converges on the lab's example at discount 1 is a named timeout; judged with
the student's own evaluation and improvement steps first, with the grader's only when that fails, the better
verdict kept and the feedback saying which reading gave it."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from grader.lab.checks.base import CallRecord, Verdict
from grader.lab.editions import edition_of
from grader.lab.rl2.checks.mdp_calls import cases
from grader.sandbox.outcome import OutcomeStatus
from reference.oracles.mdp import optimal_solution
from reference.rl2 import solutions
from tests.grader.lab.rl2.support import SEED, judged, judged_outcomes, outcome, settings, wire

EXAMPLE = next(index for index, case in enumerate(cases(SEED)) if case.key == "example")
EXAMPLE_DISCOUNTED = next(index for index, case in enumerate(cases(SEED)) if case.key == "example_0.9")
GRID = next(index for index, case in enumerate(cases(SEED)) if case.key == "grid")
OWN = "policy_iteration was called with your own iter_policy_eval and policy_improvement."
GRADERS = "policy_iteration was called with the grader's own iter_policy_eval and policy_improvement (the lab's algorithms) in place of yours, so a mistake in those counts only in their own problems."  # noqa: E501


def test_the_reference_passes_with_its_own_steps_and_the_feedback_says_so() -> None:
    verdict = judged("v2024", "policy_iteration", solutions.policy_iteration)
    assert verdict.status == "passed", verdict.feedback
    assert OWN in verdict.feedback
    assert {call.provided for call in _plan("v2024")} == {()}


def _check(edition: str = "v2024") -> Any:
    return edition_of(edition).registry.problem("policy_iteration").check


@pytest.mark.parametrize(
    ("edition", "names"),
    [
        ("v2018", ("compute_policy_v", "extract_policy")),
        ("v2024", ("iter_policy_eval", "policy_improvement")),
    ],
)
def test_the_second_reading_binds_the_editions_steps_only_when_the_first_did_not_pass(
    edition: str, names: tuple[str, str]
) -> None:
    chosen = settings(edition, "policy_iteration")
    failed, passed = Verdict("failed", 0.0, "wrong"), Verdict("passed", 1.0, "right")
    again = _check(edition).second_plan(chosen, failed, {}, SEED)
    assert {call.provided for call in again} == {names}
    assert [call.args[0].name for call in again] == [call.args[0].name for call in _plan(edition)]
    assert _check(edition).second_plan(chosen, passed, {}, SEED) == []
    for status in ("error", "timeout", "missing"):
        assert _check(edition).second_plan(chosen, Verdict(status, 0.0, "x"), {}, SEED)


@pytest.mark.parametrize(("helpers", "provided"), [("grader", True), ("student", False)])
def test_with_one_reading_chosen_there_is_no_second(helpers: str, provided: bool) -> None:
    chosen = settings("v2024", "policy_iteration", helpers=helpers)
    assert {bool(call.provided) for call in _plan("v2024", helpers=helpers)} == {provided}
    assert _check().second_plan(chosen, Verdict("failed", 0.0, "wrong"), {}, SEED) == []


def test_the_graders_reading_is_kept_only_when_it_is_better_and_the_feedback_says_which() -> None:
    chosen = settings("v2024", "policy_iteration")
    own = Verdict("error", 0.0, f"too many values to unpack. {OWN}")
    graders = Verdict("passed", 1.0, f"all right. {GRADERS}")
    kept = _check().keep(chosen, own, graders)
    assert kept.status == "passed" and kept.fraction == 1.0
    assert (
        GRADERS in kept.feedback and "With your own functions it was error: too many values" in kept.feedback
    )
    assert kept.measurements["reading"] == "grader"
    worse = Verdict("failed", 0.0, f"not optimal. {GRADERS}")
    kept = _check().keep(chosen, own, worse)
    assert kept.status == "error" and kept.feedback.startswith(own.feedback)
    assert "Judged again with the grader's own functions in place of yours, it was failed" in kept.feedback
    assert kept.measurements["reading"] == "own"


def test_the_judge_reads_the_reading_from_the_calls() -> None:
    """A call that bound the grader's steps says so, whatever the settings: the judge reads the calls."""
    check, chosen = _check(), settings("v2024", "policy_iteration")
    records = []
    for call in check.second_plan(chosen, Verdict("failed", 0.0, "wrong"), {}, SEED):
        args = [arg.as_table() if hasattr(arg, "as_table") else arg for arg in call.args]
        records.append(CallRecord(outcome(call, wire(solutions.policy_iteration(*args))), []))
    verdict = check.judge(chosen, records)
    assert verdict.status == "passed" and GRADERS in verdict.feedback, verdict.feedback


def _plan(edition: str, **changes: Any) -> list[Any]:
    return _check(edition).plan(settings(edition, "policy_iteration", **changes), {}, SEED)


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


def test_a_start_that_never_converges_on_the_labs_example_is_a_named_timeout() -> None:
    verdict = judged_outcomes("v2024", "policy_iteration", _timing_out(EXAMPLE))
    assert verdict.status == "timeout"
    assert "did not return within 20 seconds" in verdict.feedback
    assert "your start policy never converges" in verdict.feedback
    assert "walk 0 -> 1 -> 0" in verdict.feedback and "np.ones(nS, dtype=int)" in verdict.feedback


@pytest.mark.parametrize("index", [EXAMPLE_DISCOUNTED, GRID], ids=["below-discount-1", "every-policy-ends"])
def test_a_timeout_where_every_policy_has_a_value_is_not_blamed_on_the_start(index: int) -> None:
    verdict = judged_outcomes("v2024", "policy_iteration", _timing_out(index))
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
