"""The contract every per-problem check follows, and the outcome mapping they share."""

from __future__ import annotations

import functools
import gc
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ParamSpec, Protocol, TypeVar, runtime_checkable

from grader.lab.ids import ProblemId
from grader.lab.settings import ProblemConfig
from grader.report import Status
from grader.sandbox.outcome import Call, CallOutcome, FunctionInfo, OutcomeStatus, PlainValue

if TYPE_CHECKING:
    from grader.sandbox.replay import Replay

__all__ = [
    "CallRecord",
    "ProblemCheck",
    "ProblemId",
    "SecondReading",
    "Status",
    "Verdict",
    "judged_when_all_returned",
    "outcome_verdict",
]


P = ParamSpec("P")
R = TypeVar("R")
CheckT = TypeVar("CheckT")
SettingsT = TypeVar("SettingsT")
ConfigT_contra = TypeVar("ConfigT_contra", bound=ProblemConfig, contravariant=True)


@dataclass(frozen=True)
class CallRecord:
    """One sandboxed call and the trusted replays of the episodes it played.

    Attributes:
        outcome: What the sandbox reported for the call.
        replays: ``replay_episode(log)`` for each log in ``outcome.episodes``, same order.
    """

    outcome: CallOutcome
    replays: list[Replay]


@dataclass(frozen=True)
class Verdict:
    """A problem's result.

    Attributes:
        status: One of ``passed``, ``failed``, ``error``, ``timeout``, ``missing``, ``skipped`` (not run:
            no verdict needed the calls).
        fraction: Share of the problem's points earned, 0..1.
        feedback: What was expected, what was measured, the likely cause and what to do.
        measurements: JSON-serialisable numbers behind the verdict; deterministic for a given run.
    """

    status: Status
    fraction: float
    feedback: str
    measurements: dict[str, PlainValue] = field(default_factory=dict)


class ProblemCheck(Protocol[ConfigT_contra]):
    """Plans the calls one problem needs and judges their outcomes (pure: no I/O), typed by its settings.

    The registry entry (`grader.lab.registry.Problem`) pairs a check with its settings model, and
    `Problem.settings` hands it settings of exactly that model: a check never narrows its configuration.
    """

    def plan(self, settings: ConfigT_contra, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """The calls to run, given the functions the submission defines and the problem's seed.

        `seed` is the problem's sandbox seed (`grader.grading.execution.problem_seed(grading seed, problem)`):
        a check whose inputs are drawn by the parent (the second lab's MDPs, values and policies) draws them
        from it, so another grading seed grades on unseen inputs and the same seed plans the same calls.
        Checks whose randomness is the episodes' (the first lab's) ignore it: the sandbox seeds those.
        """
        ...

    def judge(self, settings: ConfigT_contra, records: Sequence[CallRecord]) -> Verdict:
        """The verdict for the planned calls' records (same order as planned; each record's `outcome.call` is
        the parent's planned call, so what a call was asked can be read from it)."""
        ...


@runtime_checkable
class SecondReading(Protocol[ConfigT_contra]):
    """A check that may judge its problem a second way when the first verdict is not full marks.

    The second lab's `policy_iteration` and `frozen_lake` call the student's other functions; a mistake in
    those counts in their own problems, so when the student's own functions give a verdict short of full
    marks, the problem is judged again with the grader's own definitions bound in their place
    (`Call.provided`) and the better verdict is kept. "A mistake counts once" only ever helps: the first
    reading is always the student's own. The runner (`grader.grading.execution.run_problem`) makes the
    second reading's calls in the same sandbox after the first verdict, only when `second_plan` asks for
    them, and judges them with the same `judge`.
    """

    def second_plan(
        self, settings: ConfigT_contra, first: Verdict, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """The calls of the second reading, or [] when the first verdict stands (`functions` and `seed` as
        `ProblemCheck.plan` gets them)."""
        ...

    def keep(self, settings: ConfigT_contra, first: Verdict, second: Verdict) -> Verdict:
        """The verdict kept of the two readings (the better), its feedback saying which reading gave it."""
        ...


def better_reading(first: Verdict, second: Verdict) -> Verdict:
    """The better of a `SecondReading` check's two verdicts, the feedback saying which reading gave it.

    The second (the grader's functions in place of the student's) is kept only when it earns more of the
    points; ties keep the student's own. Each verdict's feedback already says how its calls were made.
    """
    if second.fraction > first.fraction:
        return Verdict(
            second.status,
            second.fraction,
            f"{second.feedback} (With your own functions it was {first.status}: {first.feedback})",
            {**second.measurements, "reading": "grader", "own_reading_status": first.status},
        )
    return Verdict(
        first.status,
        first.fraction,
        f"{first.feedback} (Judged again with the grader's own functions in place of yours, it was {second.status}; the better reading is kept.)",  # noqa: E501
        {**first.measurements, "reading": "own", "grader_reading_status": second.status},
    )


def paused_gc(judge: Callable[P, R]) -> Callable[P, R]:
    """Run a judge with the cyclic garbage collector paused (restored afterwards).

    Judging walks tens of thousands of replayed episodes and builds as many small objects; each
    automatic collection would rescan every live object of the records, which made judging 3-4x slower.
    The objects built form no cycles, so nothing is lost by collecting later.
    """

    @functools.wraps(judge)
    def paused(*args: P.args, **kwargs: P.kwargs) -> R:
        enabled = gc.isenabled()
        gc.disable()
        try:
            return judge(*args, **kwargs)
        finally:
            if enabled:
                gc.enable()

    return paused


_NOT_IMPLEMENTED = "NotImplementedError"

RESET_SLACK = 8
"""Resets beyond twice the planned games a call may record (`grader.lab.checks.integrity.games_budget`)."""


def _is_not_implemented(outcome: CallOutcome) -> bool:
    return outcome.status is OutcomeStatus.EXCEPTION and _NOT_IMPLEMENTED in outcome.message


def _call_text(call: Call) -> str:
    arguments = [
        f"<{'x'.join(map(str, arg.shape))} array>" if hasattr(arg, "shape") else repr(arg)
        for arg in call.args
    ]
    arguments += [f"{name}={value!r}" for name, value in call.kwargs.items()]
    return f"{call.function}({', '.join(arguments)})"


def _over_budget_text(outcome: CallOutcome) -> str:
    """A wrong answer, described: the call played far more than the games it is graded on."""
    call = outcome.call
    budget = call.budget
    games = None if budget is None else max((budget.max_episodes - RESET_SLACK) // 2, 0)
    planned = (
        ""
        if games is None
        else f"; one call of {call.function}() is graded on {games} game{'' if games == 1 else 's'}"
    )
    return (
        f"{_call_text(call)}: {outcome.message}{planned}, so this call's result is not the one asked for. "
        f"Play exactly the games one call of {call.function}() is asked to play, each until it ends, and return that call's result (the grader calls it again for more games)"  # noqa: E501
    )


def outcome_verdict(records: Sequence[CallRecord]) -> Verdict | None:
    """The verdict implied by the sandbox outcomes alone, or None when every call returned normally.

    Shared by all checks so the same outcome always reads the same way: a missing function or a
    ``NotImplementedError`` (or an untouched stub, whatever its parameters) is "missing", a timeout is
    "timeout", a call that played far more games than it is graded on (beyond its `CallBudget`) is
    "failed" with a description of what it did (a wrong answer, not a crash), any other non-OK outcome
    (import error, exception, crash, invalid value, ...) is "error" with the sandbox's own
    student-readable message.

    Args:
        records: The problem's call records in planned order.

    Returns:
        A verdict scoring 0 for the first call that did not return normally, else None.
    """
    failed = [record.outcome for record in records if record.outcome.status is not OutcomeStatus.OK]
    if not failed:
        return None
    measurements: dict[str, PlainValue] = {
        "calls": len(records),
        "calls_ok": len(records) - len(failed),
        "outcome": str(failed[0].status.value),
    }
    missing = next((o for o in failed if o.status is OutcomeStatus.MISSING_FUNCTION), None)
    if missing is not None:
        return Verdict("missing", 0.0, missing.message, measurements)
    not_attempted = next((o for o in failed if _is_not_implemented(o)), None)
    if not_attempted is not None:
        feedback = (
            f"{_call_text(not_attempted.call)} raised NotImplementedError: not attempted yet. "
            f"Replace the `raise NotImplementedError` with your solution."
        )
        return Verdict("missing", 0.0, feedback, measurements)
    first = failed[0]
    if first.status is OutcomeStatus.EPISODE_LIMIT:
        return Verdict("failed", 0.0, _over_budget_text(first), measurements)
    status: Status = "timeout" if first.status is OutcomeStatus.TIMEOUT else "error"
    return Verdict(status, 0.0, f"{_call_text(first.call)}: {first.message}", measurements)


def judged_when_all_returned(
    judge: Callable[[CheckT, SettingsT, Sequence[CallRecord]], Verdict],
) -> Callable[[CheckT, SettingsT, Sequence[CallRecord]], Verdict]:
    """Judge only records whose calls all returned normally; else give `outcome_verdict(records)`."""

    @functools.wraps(judge)
    def judged(check: CheckT, settings: SettingsT, records: Sequence[CallRecord]) -> Verdict:
        early = outcome_verdict(records)
        return early if early is not None else judge(check, settings, records)

    return judged
