"""A problem only test registries declare: a fake `echo(n)` check, as a required and as an optional entry."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict
from grader.lab.checks.integrity import NO_EPISODES
from grader.lab.problems import PROBLEMS
from grader.lab.registry import Problem, Registry
from grader.lab.settings import ProblemConfig
from grader.sandbox.outcome import Call, FunctionInfo

ECHO_SOURCE = "def echo(n):\n    return n\n"
"""A submission that passes the echo problem."""


class EchoConfig(ProblemConfig):
    """`echo(n)`: every field has a default, so an optional echo problem's table may be left out."""

    call_seconds: float = Field(default=20.0, gt=0.0, description="Wall-clock limit of one call.")
    expected_seconds: float = Field(default=1.0, ge=0.0, description="Typical total time of the calls.")
    answer: int = Field(default=42, description="The n echo(n) is called with and must return.")


@dataclass(frozen=True)
class EchoCheck:
    """echo(answer) must return the answer; it plays no episodes."""

    def plan(self, settings: EchoConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """One unrecorded call echo(answer) (the seed unused)."""
        return [Call("echo", (settings.answer,), record_episodes=False, budget=NO_EPISODES)]

    def judge(self, settings: EchoConfig, records: Sequence[CallRecord]) -> Verdict:
        """Passed when the call returned the answer."""
        early = outcome_verdict(records)
        if early is not None:
            return early
        returned = records[0].outcome.value
        if returned != settings.answer:
            return Verdict("failed", 0.0, f"echo({settings.answer}) returned {returned!r}", {"returned": 0})
        return Verdict("passed", 1.0, f"echo({settings.answer}) returned it", {"returned": settings.answer})


ECHO = Problem(id="echo", title="Problem E: echo", points=2.0, config=EchoConfig, check=EchoCheck())
OPTIONAL_ECHO = Problem(
    id="echo", title="Problem E: echo", points=2.0, config=EchoConfig, check=EchoCheck(), enabled=False
)
WITH_ECHO = Registry((*PROBLEMS, ECHO))
"""The lab's problems and a required echo problem."""
WITH_OPTIONAL_ECHO = Registry((*PROBLEMS, OPTIONAL_ECHO))
"""The lab's problems and an echo problem disabled by default, whose table may be left out."""
