"""The messages the child sends, declared: `ReadyMessage`, `ImportErrorMessage` and `ResultMessage`.

`grader.sandbox.child.harness` and `grader.sandbox.child.calls` write them. The runner sizes every frame
(`FrameLimits.excess`), parses it strictly (`parse_payload`) and validates it against these models
(pydantic, strict, no other fields), so a forged frame becomes an `INVALID_VALUE` outcome that says what
was wrong, never a grader error. Strings are cleaned as they are validated (`grader.sandbox.text`). A
result's `value` and `episodes` are validated afterwards, by `decode_value` and `episodes_from_plain`
with the call's budget.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, Field, TypeAdapter, ValidationError, field_validator

from grader.sandbox.boundary import STRICT, at_most, problem
from grader.sandbox.child.calls import MAX_COMPAT_EVENTS
from grader.sandbox.child.importer import MAX_LISTED_NAMES, MAX_LISTED_PARAMETERS
from grader.sandbox.outcome import CompatEventRecord, FunctionInfo, OutcomeStatus, ParameterInfo
from grader.sandbox.text import EVENT_CHARS, MESSAGE_CHARS, NAME_CHARS, clean_text

ChildStatus = Literal[
    "ok",
    "exception",
    "missing_function",
    "bad_signature",
    "invalid_value",
    "output_too_large",
    "memory_limit",
    "episode_limit",
]
"""How a call may end by the child's own account (each an `OutcomeStatus` value); the other statuses are
the parent's findings (timeout, killed, exited...)."""

Name = Annotated[str, AfterValidator(lambda text: clean_text(text, NAME_CHARS))]
Text = Annotated[str, AfterValidator(lambda text: clean_text(text, MESSAGE_CHARS))]


class _Message(BaseModel):
    model_config = STRICT | {"frozen": True}


class ParameterMessage(_Message):
    """One parameter of a student function, as `inspect.signature` saw it."""

    name: Name
    kind: Name
    has_default: bool


class FunctionMessage(_Message):
    """A top-level name of the submission: callable or not, and its parameters."""

    parameters: Annotated[list[ParameterMessage], at_most(MAX_LISTED_PARAMETERS)]
    is_callable: bool


class ReadyMessage(_Message):
    """The submission was imported; these are its top-level names."""

    type: Literal["ready"]
    functions: Annotated[dict[str, FunctionMessage], at_most(MAX_LISTED_NAMES)]

    def function_table(self) -> dict[str, FunctionInfo]:
        """The names (cleaned) and their signatures as the runner exposes them."""
        table: dict[str, FunctionInfo] = {}
        for raw_name, function in self.functions.items():
            name = clean_text(raw_name, NAME_CHARS)
            parameters = tuple(ParameterInfo(p.name, p.kind, p.has_default) for p in function.parameters)
            table[name] = FunctionInfo(name, function.is_callable, parameters)
        return table


class ImportErrorMessage(_Message):
    """The submission could not be imported: a one-line message and the student's traceback."""

    type: Literal["import_error"]
    message: Text
    traceback: Text

    def explanation(self) -> str:
        """The message, then the traceback when there is one."""
        return f"{self.message}\n\n{self.traceback}" if self.traceback else self.message


class ResultMessage(_Message):
    """How one call ended; `value` and `episodes` are still as sent (decoded by the runner)."""

    type: Literal["result"]
    id: int
    nonce: str
    status: ChildStatus
    value: Any
    message: Text
    traceback: Text
    episodes: Any
    compat_events: Annotated[list[CompatEventRecord], at_most(MAX_COMPAT_EVENTS)]
    wall_time: Annotated[float, Field(ge=0, lt=1e9)]

    @field_validator("compat_events")
    @classmethod
    def _clean_events(cls, events: list[CompatEventRecord]) -> list[CompatEventRecord]:
        return [
            CompatEventRecord(
                kind=clean_text(event.kind, EVENT_CHARS),
                env_id=clean_text(event.env_id, EVENT_CHARS),
                detail=clean_text(event.detail, EVENT_CHARS),
            )
            for event in events
        ]

    @property
    def outcome_status(self) -> OutcomeStatus:
        """The status as the parent reports it."""
        return OutcomeStatus(self.status)

    def explanation(self) -> str:
        """What the student is told: the message (none for OK), then the traceback when there is one."""
        message = self.message if self.status != "ok" else ""
        return f"{message}\n\n{self.traceback}" if self.traceback else message


_FIRST_MESSAGE: TypeAdapter[ReadyMessage | ImportErrorMessage] = TypeAdapter(
    Annotated[ReadyMessage | ImportErrorMessage, Field(discriminator="type")]
)


def first_message(frame: dict[str, Any]) -> ReadyMessage | ImportErrorMessage | str:
    """The child's first frame as a message, or what is wrong with it (for a forged-frame outcome)."""
    try:
        return _FIRST_MESSAGE.validate_python(frame, strict=True)
    except ValidationError as error:
        return problem(error, "the first frame")


def result_message(frame: dict[str, Any]) -> ResultMessage | str:
    """A result frame as a message, or what is wrong with it (for a forged-frame outcome)."""
    try:
        return ResultMessage.model_validate(frame, strict=True)
    except ValidationError as error:
        return problem(error, "a result frame")
