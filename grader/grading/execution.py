"""Grade one problem of one submission: sandboxed calls, trusted replays, the check's verdict.

How a problem is run (`run_problem`):

- **One reading, or two.** The check's planned calls are made in order (until the verdict can no longer
  change) and judged. A check that is also a `SecondReading` may then ask, only when that verdict is not
  a pass, for a second reading's calls (the second lab's policy_iteration and frozen_lake, made again
  with the grader's own steps bound in place of the student's); they are made in the same sandbox, judged
  by the same `judge`, and the check keeps the better verdict. Both readings' output and time count.

- **No student CPU where no verdict needs it.** `run_problem` hands a plan the submission's functions on
  demand (`grader.grading.execution.FunctionsOnDemand`): the sandbox child starts (and imports the submission)
  only when the plan reads them or the first call is made, so a plan without calls costs no child.
  `find_qvalues` plans none unless its problem is worth points or `[problems.find_qvalues]` says `run =
  "always"` (`FindQvaluesConfig.called`; default `run = "when_scored"`: `taxi(q_table)` gets the grader's
  exact table, and a `taxi()` that trains its own table calls `find_qvalues` inside its own call); its verdict
  is then `skipped` (0 of 0, feedback saying why and how to have it run). `skipped` is a status of `Verdict`
  and `ProblemResult`: `Report.full_marks` and Gradescope's test status count it as nothing failed, progress
  shows `[SKIPPED]`. One sandbox child per problem stays (not one per worker for all problems of a
  submission): `bench/speed.py` measured the saving (a child start, import and teardown per problem: 1 to 3 s
  each on the shared 2-core machine, isolation set-up a few hundredths of it; off the critical path, which is
  the longest problem) against the cost: module-level state (a notebook's global env, Q-table or list) would
  carry from one problem into the next, so a problem's report would depend on which problems xdist happened to
  run before it in that worker; one child's life-long CPU limit, memory growth and restart after a fatal
  outcome would be shared too. Weighed again for issue 44: a child per submission that imports numpy and
  gymnasium once and forks a fresh process per problem inside the same sandbox would save the interpreter
  start and imports of each later problem (about 0.16 s of CPU each), but that fork's problems would share the
  sandbox's private /tmp, System V IPC, process-count limit and user id, so a process one problem left
  behind (or that stopped or killed the forking parent) could reach the next problem's verdict; not built.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from grader.lab.assignment import AssignmentConfig
from grader.lab.checks.base import CallRecord, ProblemCheck, SecondReading, Verdict
from grader.lab.checks.integrity import replay_call, settled_by
from grader.lab.registry import ProblemId
from grader.lab.settings import ProblemConfig
from grader.lab.showcase import showcase_episode
from grader.report import (
    IsolationSummary,
    LayerSummary,
    ProblemResult,
    ProblemRun,
    Timings,
    cap_output,
    plain_json,
)
from grader.sandbox import (
    Call,
    CallOutcome,
    CompatEventRecord,
    FunctionInfo,
    IsolationPolicy,
    IsolationReport,
    Sandbox,
)
from grader.sandbox.child.cells import RUN_CELLS
from grader.submission.notebook.cells import runnable_cells

MAX_COMPAT_EVENTS = 20
"""Distinct compatibility events kept per problem: enough to explain, bounded for 100-call problems."""


def problem_seed(grading_seed: int, problem: str) -> int:
    """The sandbox seed of one problem: a stable hash of (grading seed, problem id), 63 bits.

    Independent of the worker, the order of the tests and the other problems, so a problem gets the same
    calls and episodes whether it is graded alone, under xdist or in a batch.
    """
    digest = hashlib.sha256(f"gymgrade:{grading_seed}:{problem}".encode()).digest()
    return int.from_bytes(digest[:8], "big") >> 1


def isolation_summary(isolation: IsolationReport) -> IsolationSummary:
    """The sandbox's isolation report for the report: ``full``, ``layers`` and a readable ``summary``."""
    return IsolationSummary(
        full=isolation.full,
        layers=[
            LayerSummary(
                name=layer.name,
                active=layer.active,
                required=layer.required,
                detail=layer.detail,
                remedy=layer.remedy,
            )
            for layer in isolation.layers
        ],
        summary=isolation.summary(),
    )


class FunctionsOnDemand(Mapping[str, FunctionInfo]):
    """The submission's functions, read from the sandbox only when a plan looks at them.

    The child starts (and imports the submission) on the first read or the first call, so a problem whose
    plan calls nothing (find_qvalues when no verdict needs it) costs no child and no import.
    """

    def __init__(self, sandbox: Sandbox) -> None:
        self._sandbox = sandbox

    def __getitem__(self, name: str) -> FunctionInfo:
        return self._sandbox.functions[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._sandbox.functions)

    def __len__(self) -> int:
        return len(self._sandbox.functions)


def run_problem(
    submission: Path,
    problem: ProblemId,
    *,
    config: AssignmentConfig,
    grading_seed: int,
    policy: IsolationPolicy,
    shown_name: str = "",
) -> ProblemRun:
    """Run one problem's planned calls in a fresh sandbox, replay every episode and judge.

    A student's failure (import error, crash, timeout, wrong values) is part of the returned result;
    only a failure of the grader itself raises.

    Args:
        submission: The student's file.
        problem: Which problem to grade (one of the configuration's registry).
        config: The assignment configuration.
        grading_seed: The grading seed; the problem's sandbox seed derives from it and the problem id.
        policy: Whether weaker isolation than full is acceptable.

    Returns:
        The problem's result and the sandbox's isolation report.

    Raises:
        grader.sandbox.errors.IsolationUnavailable: Full isolation was required and is not available.
    """
    started = time.perf_counter()
    entry = config.registry.problem(problem)
    check, settings = entry.check, entry.settings(config)
    seed = problem_seed(grading_seed, problem)
    limits = config.sandbox.to_limits(settings.call_seconds)
    with Sandbox(submission, seed=seed, limits=limits, policy=policy, shown_name=shown_name) as sandbox:
        planned = check.plan(settings, FunctionsOnDemand(sandbox), seed)
        records, verdict = _reading(sandbox, submission, check, settings, planned)
        if isinstance(check, SecondReading):
            again = check.second_plan(settings, verdict, FunctionsOnDemand(sandbox), seed)
            if again:
                more, second = _reading(sandbox, submission, check, settings, again)
                records, verdict = records + more, check.keep(settings, verdict, second)
        isolation = isolation_summary(sandbox.isolation)
    outcomes = [record.outcome for record in records]
    wall_seconds = time.perf_counter() - started
    student_seconds = sum(outcome.wall_time for outcome in outcomes)
    fraction = min(max(verdict.fraction, 0.0), 1.0)
    measurements = plain_json(verdict.measurements)
    result = ProblemResult(
        id=problem,
        title=settings.title,
        status=verdict.status,
        score=round(settings.points * fraction, 6),
        max_score=settings.points,
        feedback=verdict.feedback,
        measurements=measurements if isinstance(measurements, dict) else {"value": measurements},
        output=cap_output(student_output(outcomes)),
        compat_events=_distinct_events(outcomes),
        seed=seed,
        visibility=settings.visibility,
        replay=showcase_episode(entry.showcase, records),
        timings=Timings(
            wall_seconds=wall_seconds,
            student_seconds=student_seconds,
            overhead_seconds=max(wall_seconds - student_seconds, 0.0),
        ),
    )
    return ProblemRun(submission=str(submission), result=result, isolation=isolation)


def _reading(
    sandbox: Sandbox,
    submission: Path,
    check: ProblemCheck[Any],
    settings: ProblemConfig,
    calls: Sequence[Call],
) -> tuple[list[CallRecord], Verdict]:
    """Make one reading's calls in order (until the verdict can no longer change) and judge them."""
    games = settings.game_rules()
    records: list[CallRecord] = []
    stopped: str | None = None
    for call in calls:
        if call.function == RUN_CELLS:  # the cells are the submission's, known here, not to the plan
            call = replace(call, args=(runnable_cells(submission),))
        records.append(replay_call(sandbox.call(call), games))
        stopped = settled_by(records[-1], games)
        if stopped is not None:
            break
    verdict = check.judge(settings, records)
    cells_failed = bool(records) and records[-1].outcome.call.function == RUN_CELLS  # the check says so
    if stopped is not None and len(records) < len(calls) and not cells_failed:
        verdict = _stopped_early(verdict, stopped, len(records), len(calls))
    return records, verdict


def _stopped_early(verdict: Verdict, reason: str, made: int, planned: int) -> Verdict:
    """The verdict of a problem whose calls stopped once it could no longer change, saying so."""
    measurements = {**verdict.measurements, "calls_planned": planned, "calls_made": made}
    note = (
        f" Grading stopped after call {made} of {planned}: "
        f"{reason}, so no later call could change the verdict."
    )
    feedback = verdict.feedback if verdict.feedback.endswith((".", "!", "?")) else f"{verdict.feedback}."
    return Verdict(verdict.status, verdict.fraction, feedback + note, measurements)


def student_output(outcomes: Sequence[CallOutcome]) -> str:
    """Everything the student's calls printed, stdout then stderr per call, in call order."""
    return "".join(outcome.stdout + outcome.stderr for outcome in outcomes)


def _distinct_events(outcomes: Sequence[CallOutcome]) -> list[CompatEventRecord]:
    distinct = dict.fromkeys(event for outcome in outcomes for event in outcome.compat_events)
    return list(distinct)[:MAX_COMPAT_EVENTS]
