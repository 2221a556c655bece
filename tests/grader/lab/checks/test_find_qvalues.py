"""find_qvalues: called only when a verdict needs it; a valid table gets its exact greedy return reported."""

import numpy as np
import pytest

from grader.lab.checks.base import CallRecord
from grader.lab.checks.find_qvalues import NOT_RUN_FEEDBACK
from grader.lab.problems import PROBLEMS
from grader.sandbox.outcome import Call, CallOutcome, OutcomeStatus
from reference.oracles import optimal_q_table

from .support import small_config


def _judge(value: object):  # type: ignore[no-untyped-def]
    settings = small_config("find_qvalues", run="always")
    (call,) = PROBLEMS.problem("find_qvalues").check.plan(settings, {}, 0)
    assert (call.function, call.args, call.record_episodes) == ("find_qvalues", ("Taxi-v3",), False)
    outcome = CallOutcome(
        Call("find_qvalues", ("Taxi-v3",), record_episodes=False),
        OutcomeStatus.OK,
        value,
        [],
        [],
        "",
        "",
        "",
        1.0,
        3,
    )
    return PROBLEMS.problem("find_qvalues").check.judge(settings, [CallRecord(outcome, [])])


def test_optimal_table_reports_the_optimal_return() -> None:
    verdict = _judge(optimal_q_table(0.6))
    assert verdict.status == "passed"
    # 7.93: a regression snapshot of the exact oracle `optimal_return()` (checked by simulation and against
    # the Bellman equation in tests/reference/oracles/test_taxi_oracle.py).
    assert verdict.measurements["greedy_mean_return"] == pytest.approx(7.93, abs=1e-9)
    assert verdict.measurements["optimal_mean_return"] == pytest.approx(7.93, abs=1e-9)


@pytest.mark.parametrize(
    ("value", "found"),
    [
        (np.zeros((500, 5)), "an array of shape (500, 5) and dtype float64"),
        (np.full((500, 6), np.nan), "an array of shape (500, 6) and dtype float64"),
        ("table", "'table'"),
    ],
    ids=["wrong-shape", "not-finite", "string"],
)
def test_invalid_tables_fail(value: object, found: str) -> None:
    verdict = _judge(value)
    assert verdict.status == "failed"
    assert verdict.feedback == (
        "find_qvalues('Taxi-v3') must return a finite 500 x 6 array of numbers (one row per "
        f"state, one column per action); it returned {found}."
    )


@pytest.mark.parametrize(
    ("updates", "called"),
    [
        ({}, False),
        ({"run": "when_scored"}, False),
        ({"run": "always"}, True),
        ({"points": 1.0}, True),
        ({"points": 1.0, "run": "when_scored"}, True),
    ],
    ids=["default", "when-scored-at-0-points", "always", "scored", "when-scored-and-scored"],
)
def test_find_qvalues_is_called_only_when_scored_or_asked_for(
    updates: dict[str, object], called: bool
) -> None:
    settings = small_config("find_qvalues", **updates)
    calls = PROBLEMS.problem("find_qvalues").check.plan(settings, {}, 0)
    assert [call.function for call in calls] == (["find_qvalues"] if called else [])


def test_not_calling_find_qvalues_is_a_skipped_verdict_that_says_why() -> None:
    verdict = PROBLEMS.problem("find_qvalues").check.judge(small_config("find_qvalues"), [])
    assert (verdict.status, verdict.fraction, verdict.measurements) == ("skipped", 0.0, {"calls_made": 0})
    assert verdict.feedback == NOT_RUN_FEEDBACK
    assert NOT_RUN_FEEDBACK == (
        "Not run: find_qvalues is worth 0 points and no other check needs its table (taxi(q_table) receives "
        "the grader's exact optimal table), so it was not called and its training cost you no time. To have "
        "your table checked anyway, grade with an assignment configuration whose [problems.find_qvalues] has "
        'run = "always" (gymgrade check --config FILE).'
    )
