"""What a sandboxed call asks for and what it produced: `Call` (with its `CallBudget`), `CallOutcome`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING, Any, TypeAlias

from pydantic import BaseModel, ConfigDict, Field

from grader.sandbox.child.cells import RUN_CELLS
from grader.sandbox.child.frames import ENV_NAME_OR_OBJECT, EnvArgument, MdpArgument
from grader.sandbox.child.provided import PROVIDED
from grader.sandbox.limits import CallBudget

__all__ = [
    "ENV_NAME_OR_OBJECT",
    "IMPORT_TIMEOUT",
    "PROVIDED",
    "RUN_CELLS",
    "Call",
    "CallOutcome",
    "EnvArgument",
    "FunctionInfo",
    "MdpArgument",
    "OutcomeStatus",
    "ParameterInfo",
    "PlainValue",
]
"""`RUN_CELLS` (the call that runs a notebook's cells), `EnvArgument` (an env passed to a call by name or
as an object the child makes; `ENV_NAME_OR_OBJECT`, the name first), `MdpArgument` (a finite MDP's table
`P`, given to each call as a fresh dict of int keys and tuples) and
`PROVIDED` (the grader's definitions a call may bind) are declared by the child, which imports nothing of
the parent; the plans use them from here."""

if TYPE_CHECKING:
    from grader.sandbox.episode_log import EpisodeLog

IMPORT_TIMEOUT = "importing your file took more than"
"""How the message of a call begins when the submission did not import within its limit (the runner's)."""

PlainValue: TypeAlias = Any
"""None, bool, int, float, str, lists and str-keyed dicts of these, or a numeric numpy array."""


class OutcomeStatus(StrEnum):
    """How a call ended. Every status but OK comes with a student-readable message."""

    OK = "ok"
    IMPORT_ERROR = "import_error"
    EXCEPTION = "exception"
    TIMEOUT = "timeout"
    MEMORY_LIMIT = "memory_limit"
    KILLED = "killed"
    EXITED = "exited"
    MISSING_FUNCTION = "missing_function"
    BAD_SIGNATURE = "bad_signature"
    OUTPUT_TOO_LARGE = "output_too_large"
    INVALID_VALUE = "invalid_value"
    EPISODE_LIMIT = "episode_limit"
    """The call reset its envs or stepped them more often than its `CallBudget` allows."""
    SANDBOX_ERROR = "sandbox_error"


@dataclass(frozen=True)
class Call:
    """One call of a student function.

    Attributes:
        function: Name of the function in the submission.
        args: Positional arguments, plain data only.
        kwargs: Keyword arguments, plain data only.
        record_episodes: Whether the child logs every episode played (False for long training runs).
        budget: The most the call may record; None keeps the sandbox-wide limits: the step limit
            (`grader.sandbox.child.recorder.DEFAULT_MAX_RECORDED_STEPS`) and `Limits.frame_bytes`.
        seconds: Wall-clock limit of this call; None keeps `Limits.call_seconds` (a problem's calls share
            one limit; running a notebook's cells before them has its own).
        provided: Names of the submission's globals the child binds, for this call only, to the grader's
            own definitions (`grader.sandbox.child.provided.PROVIDED`), e.g. sarsa0 run with the
            grader's `epsilon_decay`.
    """

    function: str
    args: tuple[PlainValue, ...] = ()
    kwargs: Mapping[str, PlainValue] = field(default_factory=dict)
    record_episodes: bool = True
    budget: CallBudget | None = None
    seconds: float | None = None
    provided: tuple[str, ...] = ()


@dataclass(frozen=True)
class ParameterInfo:
    """One parameter of a student function, as `inspect.signature` saw it in the child."""

    name: str
    kind: str
    has_default: bool


@dataclass(frozen=True)
class FunctionInfo:
    """A top-level name the submission defines and, when callable, its parameters."""

    name: str
    is_callable: bool
    parameters: tuple[ParameterInfo, ...] = ()


class CompatEventRecord(BaseModel):
    """One thing the lab-compatibility layer had to tolerate during a call (`grader.compat.events`).

    The same JSON in a call's outcome and in a problem's result: `{"kind", "env_id", "detail"}`.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: str = Field(
        description="What was tolerated: step_after_done, renamed_id, seed_replaced, api_detected..."
    )
    env_id: str = Field(description="The environment (or, for api_detected, the function) it concerns.")
    detail: str = Field(description="What happened and how often, in words.")


@dataclass(frozen=True)
class CallOutcome:
    """What one call produced.

    Attributes:
        call: The call made.
        status: How it ended.
        value: Decoded plain data; None unless status is OK.
        episodes: Episode logs recorded in the child (untrusted until replayed).
        compat_events: What the compatibility layer had to tolerate, in the order it was drained.
        stdout: The student's own output, capped (a note says how much was dropped).
        stderr: The student's error output, capped likewise.
        message: Student-readable explanation; empty only for OK.
        wall_time: Seconds spent in the student's function (or until the parent gave up).
        seed: The grading seed of this call, derived from the sandbox seed and the call's index.
    """

    call: Call
    status: OutcomeStatus
    value: PlainValue
    episodes: list[EpisodeLog]
    compat_events: list[CompatEventRecord]
    stdout: str
    stderr: str
    message: str
    wall_time: float
    seed: int
