"""frozen_lake's second reading: only when the student's own functions give a verdict short of a pass, both
lakes' calls are made again with the grader's solvers and run_simulation bound (`Call.provided`), the better
verdict kept and the feedback saying which reading gave it. The sandboxed end of it is pinned by
`submissions/rl2/mistakes/run_simulation_not_done.py` in submissions/rl2/verdicts.toml."""

from __future__ import annotations

from dataclasses import replace

import pytest

from grader.lab.checks.base import CallRecord, Verdict
from grader.lab.games import FROZEN_LAKE_GAMES
from grader.lab.rl2.checks.frozen_lake import (
    GRADERS_READING,
    STEPS_PROVIDED,
    FrozenLakeCheck,
    FrozenLakeConfig,
)
from grader.sandbox.child.provided import PROVIDED
from grader.sandbox.outcome import FunctionInfo, OutcomeStatus, ParameterInfo
from tests.grader.lab.rl2.support import outcome

from .played_support import settings

BOUND = settings(FrozenLakeConfig, "frozen_lake", FROZEN_LAKE_GAMES, episodes=20)
CHECK = FrozenLakeCheck("frozen_lake", "six")


def _functions(*names: str) -> dict[str, FunctionInfo]:
    parameters = tuple(ParameterInfo(name, "POSITIONAL_OR_KEYWORD", True) for name in names)
    return {"frozen_lake": FunctionInfo("frozen_lake", True, parameters)}


@pytest.mark.parametrize("status", ["failed", "error", "timeout", "missing"])
def test_the_second_reading_makes_both_lakes_calls_with_the_graders_steps(status: str) -> None:
    functions = _functions("basic_case", "M", "render")
    again = CHECK.second_plan(BOUND, Verdict(status, 0.0, "x"), functions, 7)
    first = CHECK.plan(BOUND, functions, 7)[:2]
    assert (
        [call.args for call in again]
        == [call.args for call in first]
        == [(True, 20, False), (False, 20, False)]
    )
    assert {call.provided for call in again} == {STEPS_PROVIDED}
    assert set(STEPS_PROVIDED) <= set(PROVIDED)  # the child binds only names it provides
    assert all(
        call.function == "frozen_lake" and call.budget == f.budget
        for call, f in zip(again, first, strict=True)
    )


def test_a_passing_first_reading_has_no_second() -> None:
    assert CHECK.second_plan(BOUND, Verdict("passed", 1.0, "right"), _functions("basic_case", "M"), 7) == []


def test_the_judge_says_when_the_graders_steps_were_bound() -> None:
    own = CHECK.plan(BOUND, {}, 7)[0]
    graders = replace(own, provided=STEPS_PROVIDED)
    error = {"status": OutcomeStatus.EXCEPTION, "message": "NameError: name 'run_simulation' is not defined"}
    assert GRADERS_READING not in CHECK.judge(BOUND, [CallRecord(outcome(own, **error), [])]).feedback
    assert GRADERS_READING in CHECK.judge(BOUND, [CallRecord(outcome(graders, **error), [])]).feedback


def test_the_better_reading_is_kept() -> None:
    missing, passed = (
        Verdict("missing", 0.0, "not attempted."),
        Verdict("passed", 1.0, f"right. {GRADERS_READING}"),
    )
    kept = CHECK.keep(BOUND, missing, passed)
    assert (kept.status, kept.fraction) == ("passed", 1.0)
    assert "With your own functions it was missing: not attempted." in kept.feedback
    assert CHECK.keep(BOUND, missing, Verdict("error", 0.0, "worse")).status == "missing"
