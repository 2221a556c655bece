"""The declared messages of the child (grader/sandbox/messages.py): honest frames validate, forged ones are
refused with a sentence saying where and what, strings are cleaned on the way in."""

from __future__ import annotations

from typing import Any, get_args

import pytest

from grader.sandbox.child.calls import MAX_COMPAT_EVENTS
from grader.sandbox.messages import (
    ChildStatus,
    ImportErrorMessage,
    ReadyMessage,
    ResultMessage,
    first_message,
    result_message,
)
from grader.sandbox.outcome import CompatEventRecord, FunctionInfo, OutcomeStatus, ParameterInfo
from grader.sandbox.text import EVENT_CHARS, REPLACEMENT

READY: dict[str, Any] = {
    "type": "ready",
    "functions": {
        "add": {
            "parameters": [
                {"name": "a", "kind": "POSITIONAL_OR_KEYWORD", "has_default": False},
                {"name": "b", "kind": "POSITIONAL_OR_KEYWORD", "has_default": True},
            ],
            "is_callable": True,
        },
        "ALPHA": {"parameters": [], "is_callable": False},
    },
}
RESULT: dict[str, Any] = {
    "type": "result",
    "id": 3,
    "nonce": "ab" * 16,
    "status": "ok",
    "value": [1, 2.5],
    "message": "",
    "traceback": "",
    "episodes": [],
    "compat_events": [{"kind": "renamed_id", "env_id": "Taxi-v3", "detail": "made as Taxi-v4"}],
    "wall_time": 0.25,
}


def test_every_status_a_child_may_send_is_an_outcome_status() -> None:
    assert {OutcomeStatus(status) for status in get_args(ChildStatus)} <= set(OutcomeStatus)


def test_an_honest_ready_frame_gives_the_function_table() -> None:
    message = first_message(READY)

    assert isinstance(message, ReadyMessage)
    assert message.function_table() == {
        "add": FunctionInfo(
            "add",
            True,
            (
                ParameterInfo("a", "POSITIONAL_OR_KEYWORD", False),
                ParameterInfo("b", "POSITIONAL_OR_KEYWORD", True),
            ),
        ),
        "ALPHA": FunctionInfo("ALPHA", False, ()),
    }


def test_an_import_error_frame_gives_the_message_and_the_traceback() -> None:
    message = first_message({"type": "import_error", "message": "NameError: x", "traceback": "line 1\x00"})

    assert isinstance(message, ImportErrorMessage)
    assert message.explanation() == f"NameError: x\n\nline 1{REPLACEMENT}"


FORGED_FIRST = [
    (
        {"type": "result"},
        "the first frame: tag 'result' found using 'type' does not match any of the expected tags: 'ready', "
        "'import_error', found dict {'type': 'result'}",
    ),
    (
        {**READY, "functions": []},
        "the first frame: ready.functions: should be a valid dictionary, found list []",
    ),
    (
        {**READY, "functions": {"f": {"parameters": [{"name": 1, "kind": "k", "has_default": False}]}}},
        "the first frame: ready.functions.f.parameters[0].name: should be a valid string, found int 1",
    ),
    (
        {**READY, "functions": {"f": {"parameters": [], "is_callable": 1}}},
        "the first frame: ready.functions.f.is_callable: should be a valid boolean, found int 1",
    ),
    ({**READY, "extra": 1}, "the first frame: ready: 'extra' is not one of its fields"),
    (
        {
            **READY,
            "functions": {f"f{number}": {"parameters": [], "is_callable": True} for number in range(2001)},
        },
        "the first frame: ready.functions: should hold at most 500 entries, found 2001",
    ),
    (
        {"type": "import_error", "message": "x"},
        "the first frame: import_error: the field 'traceback' is missing",
    ),
]


@pytest.mark.parametrize(
    ("frame", "expected"),
    FORGED_FIRST,
    ids=[
        "other-type",
        "functions-not-a-dict",
        "parameter-name",
        "is-callable-int",
        "extra",
        "too-many",
        "missing",
    ],
)
def test_a_forged_first_frame_says_what_is_wrong(frame: dict[str, Any], expected: str) -> None:
    problem = first_message(frame)

    assert isinstance(problem, str)
    assert problem.startswith(expected)


def test_an_honest_result_frame_validates_with_its_events_as_records() -> None:
    message = result_message(RESULT)

    assert isinstance(message, ResultMessage)
    assert (message.outcome_status, message.value, message.wall_time, message.explanation()) == (
        OutcomeStatus.OK,
        [1, 2.5],
        0.25,
        "",
    )
    assert message.compat_events == [
        CompatEventRecord(kind="renamed_id", env_id="Taxi-v3", detail="made as Taxi-v4")
    ]


def test_result_strings_are_cleaned_and_capped() -> None:
    events = [{"kind": "k\ud800", "env_id": "e", "detail": "d" * (EVENT_CHARS + 10)}]
    message = result_message({**RESULT, "status": "exception", "message": "bad\x00", "compat_events": events})

    assert isinstance(message, ResultMessage)
    assert message.explanation() == f"bad{REPLACEMENT}"
    (event,) = message.compat_events
    assert event.kind == f"k{REPLACEMENT}"
    assert event.detail.startswith("d" * EVENT_CHARS + "\n[... 10 more characters cut]")


FORGED_RESULT = [
    ({"status": "passed"}, "a result frame: status: should be 'ok', 'exception',"),
    ({"id": True}, "a result frame: id: should be a valid integer, found bool True"),
    ({"wall_time": -1}, "a result frame: wall_time: should be greater than or equal to 0, found int -1"),
    ({"wall_time": 1e12}, "a result frame: wall_time: should be less than 1000000000"),
    ({"message": None}, "a result frame: message: should be a valid string, found NoneType None"),
    (
        {"compat_events": [{"kind": "k", "env_id": "e"}]},
        "a result frame: compat_events[0]: the field 'detail' is missing",
    ),
    (
        {"compat_events": [{"kind": "k", "env_id": "e", "detail": 3}]},
        "a result frame: compat_events[0].detail: should be a valid string, found int 3",
    ),
    (
        {"compat_events": [{"kind": "k", "env_id": "e", "detail": "d"}] * (MAX_COMPAT_EVENTS + 1)},
        "a result frame: compat_events: should hold at most 100 entries, found 101",
    ),
    ({"extra": 1}, "a result frame: 'extra' is not one of its fields"),
]


def test_too_many_events_are_refused_before_any_is_validated() -> None:
    # Every entry is invalid: had one been validated first, the first problem would name compat_events.0.
    events = [{"kind": 1}] * 1_000_000

    problem = result_message({**RESULT, "compat_events": events})

    assert problem == "a result frame: compat_events: should hold at most 100 entries, found 1000000"


@pytest.mark.parametrize(
    ("changes", "expected"),
    FORGED_RESULT,
    ids=[
        "status",
        "id-bool",
        "negative-time",
        "huge-time",
        "message-none",
        "event-missing-field",
        "event-not-str",
        "too-many-events",
        "extra",
    ],
)
def test_a_forged_result_frame_says_what_is_wrong(changes: dict[str, Any], expected: str) -> None:
    problem = result_message({**RESULT, **changes})

    assert isinstance(problem, str)
    assert problem.startswith(expected)
    assert len(problem) < 300
