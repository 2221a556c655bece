"""find_qvalues: a valid table gets its exact greedy return reported; anything else fails."""

import numpy as np
import pytest

from grader.checks.base import CallRecord
from grader.problems import PROBLEMS
from grader.sandbox.outcome import Call, CallOutcome, OutcomeStatus
from reference.oracles import optimal_q_table

from .support import small_config


def _judge(value: object):  # type: ignore[no-untyped-def]
    settings = small_config("find_qvalues")
    (call,) = PROBLEMS.problem("find_qvalues").check.plan(settings, {})
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
