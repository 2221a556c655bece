"""The outcome mapping every check shares: sandbox statuses to verdicts."""

from collections.abc import Sequence

import pytest

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, outcome_verdict
from grader.lab.checks.integrity import games_budget
from grader.sandbox.outcome import Call, CallOutcome, OutcomeStatus


def _record(status: OutcomeStatus, message: str = "", function: str = "car") -> CallRecord:
    outcome = CallOutcome(
        Call(function), status, 1 if status is OutcomeStatus.OK else None, [], [], "", "", message, 0.0, 7
    )
    return CallRecord(outcome, [])


@pytest.mark.parametrize(
    ("status", "message", "expected_status", "feedback"),
    [
        (
            OutcomeStatus.MISSING_FUNCTION,
            "your file defines no function named `car`",
            "missing",
            "your file defines no function named `car`",
        ),
        (
            OutcomeStatus.EXCEPTION,
            "car() raised NotImplementedError: Problem 4 Incomplete",
            "missing",
            "car() raised NotImplementedError: not attempted yet. Replace the `raise NotImplementedError` "
            "with your "
            "solution.",
        ),
        (
            OutcomeStatus.TIMEOUT,
            "car() did not return within 30 s",
            "timeout",
            "car(): car() did not return within 30 s",
        ),
        (
            OutcomeStatus.EXCEPTION,
            "car() raised ZeroDivisionError: division by zero",
            "error",
            "car(): car() raised ZeroDivisionError: division by zero",
        ),
        (
            OutcomeStatus.IMPORT_ERROR,
            "your file failed to import: NameError",
            "error",
            "car(): your file failed to import: NameError",
        ),
        (
            OutcomeStatus.INVALID_VALUE,
            "car() returned a MagicFloat, expected a number",
            "error",
            "car(): car() returned a MagicFloat, expected a number",
        ),
        (OutcomeStatus.MEMORY_LIMIT, "car() ran out of memory", "error", "car(): car() ran out of memory"),
    ],
    ids=[
        "missing-function",
        "not-implemented",
        "timeout",
        "exception",
        "import-error",
        "invalid-value",
        "memory",
    ],
)
def test_non_ok_outcome_maps_to_a_zero_verdict(
    status: OutcomeStatus, message: str, expected_status: str, feedback: str
) -> None:
    verdict = outcome_verdict([_record(OutcomeStatus.OK), _record(status, message)])
    assert verdict is not None
    assert (verdict.status, verdict.fraction, verdict.feedback) == (expected_status, 0.0, feedback)
    assert verdict.measurements == {"calls": 2, "calls_ok": 1, "outcome": status.value}


def test_missing_wins_over_an_earlier_error() -> None:
    verdict = outcome_verdict(
        [_record(OutcomeStatus.TIMEOUT, "slow"), _record(OutcomeStatus.MISSING_FUNCTION, "no car")]
    )
    assert verdict is not None and verdict.status == "missing"


def test_all_ok_leaves_judging_to_the_check() -> None:
    assert outcome_verdict([_record(OutcomeStatus.OK)] * 3) is None


def test_a_call_beyond_its_budget_is_a_described_wrong_answer() -> None:
    call = Call("cartpole", budget=games_budget(1, 1_000))
    message = "cartpole() played 101 games in one call (it reset its environment 101 times); the grader records at most 10 resets per call of cartpole()"  # noqa: E501
    outcome = CallOutcome(call, OutcomeStatus.EPISODE_LIMIT, None, [], [], "", "", message, 0.0, 7)
    verdict = outcome_verdict([CallRecord(outcome, [])])
    assert verdict is not None
    assert (verdict.status, verdict.fraction) == ("failed", 0.0)
    assert verdict.feedback == (
        "cartpole(): cartpole() played 101 games in one call (it reset its environment 101 times); "
        "the grader records at most 10 resets per call of cartpole(); one call of cartpole() is graded on "
        "1 game, so this call's result is not the one asked for. Play exactly the games one call of "
        "cartpole() is asked to play, each until it ends, and return that call's result (the grader calls "
        "it again for more games)"
    )
    assert "easy start" not in verdict.feedback


def test_a_judge_sees_only_records_whose_calls_all_returned() -> None:
    judged: list[int] = []

    @judged_when_all_returned
    def judge(_check: object, _settings: object, records: Sequence[CallRecord]) -> Verdict:
        judged.append(len(records))
        return Verdict("passed", 1.0, "judged")

    ok, timeout = (
        _record(OutcomeStatus.OK),
        _record(OutcomeStatus.TIMEOUT, "car() did not return within 30 s"),
    )
    assert judge(None, None, [ok, timeout]) == outcome_verdict([ok, timeout])
    assert judged == []
    assert judge(None, None, [ok, ok]).feedback == "judged"
    assert judged == [2]
