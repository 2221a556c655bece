"""Run one call request in the child and build its result frame."""

from __future__ import annotations

import functools
import inspect
import json
import time
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import gymnasium

from grader.compat import ClassicEnv, register_envs, resolve_env_id
from grader.compat import events as compat_events
from grader.sandbox.child.budget import FrameLimits, WireBudget, frame_limits
from grader.sandbox.child.cells import RUN_CELLS, run_cells
from grader.sandbox.child.errors import FrameTooLargeError, InvalidValueError, ProtocolError
from grader.sandbox.child.frames import (
    ENV_GYM_OBJECT,
    ENV_NAME,
    ENV_NAME_OR_OBJECT,
    EnvArgument,
    MdpArgument,
    decode_value,
    encode_value,
)
from grader.sandbox.child.importer import describe_exception, shortened, student_traceback
from grader.sandbox.child.log_block import NO_EPISODES, log_block
from grader.sandbox.child.provided import PROVIDED
from grader.sandbox.child.recorder import Recorder, RecordingEnv
from grader.sandbox.child.stubs import RAISING_STUB, stub_body

MAX_COMPAT_EVENTS = 100
MAX_EVENT_DETAIL = 1000
"""Characters kept of a compat event's detail (100 events stay far below the frame's allowance)."""
_CALL_FIELDS = {"type", "id", "nonce", "function", "args", "kwargs", "seed", "record", "budget"}
_OPTIONAL_CALL_FIELDS = {"provided"}


@dataclass(frozen=True)
class CallRequest:
    """A validated `call` frame."""

    call_id: int
    nonce: str
    function: str
    args: list[Any]
    kwargs: dict[str, Any]
    seed: int
    record: bool
    budget: WireBudget | None = None
    provided: tuple[str, ...] = ()


def parse_call(frame: dict[str, Any]) -> CallRequest:
    """Validate a `call` frame from the parent.

    Raises:
        ProtocolError: a field is missing, extra or of the wrong type.
    """
    if not _CALL_FIELDS <= frame.keys() <= _CALL_FIELDS | _OPTIONAL_CALL_FIELDS or frame["type"] != "call":
        raise ProtocolError(
            f"expected a call frame with fields {sorted(_CALL_FIELDS)}, found {sorted(frame)}"
        )
    checks = {
        "id": type(frame["id"]) is int,
        "nonce": type(frame["nonce"]) is str,
        "function": type(frame["function"]) is str,
        "args": type(frame["args"]) is list,
        "kwargs": type(frame["kwargs"]) is dict,
        "seed": type(frame["seed"]) is int and frame["seed"] >= 0,
        "record": type(frame["record"]) is bool,
        "provided": type(frame.get("provided", [])) is list
        and all(type(name) is str and name in PROVIDED for name in frame.get("provided", [])),
    }
    wrong = [name for name, ok in checks.items() if not ok]
    if wrong:
        raise ProtocolError(f"call frame fields of the wrong type: {', '.join(wrong)}")
    try:
        args = decode_value(frame["args"], "the call's arguments", allow_envs=True)
        kwargs = decode_value(frame["kwargs"], "the call's keyword arguments", allow_envs=True)
        budget = WireBudget.from_plain(frame["budget"])
    except InvalidValueError as error:
        raise ProtocolError(error.message) from None
    except ValueError as error:
        raise ProtocolError(str(error)) from None
    return CallRequest(
        frame["id"],
        frame["nonce"],
        frame["function"],
        args,
        kwargs,
        frame["seed"],
        frame["record"],
        budget,
        tuple(frame.get("provided", [])),
    )


def run_call(
    module: ModuleType,
    request: CallRequest,
    recorder: Recorder,
    submission: Path,
    max_frame: int,
    name: str | None = None,
) -> bytes:
    """Call the student's function as `request` says and return the encoded result frame payload; a
    traceback names the file `name` (the harness's `--name`), `submission.name` when None.

    `SystemExit` propagates (the process ends and the runner reports the exit); every other
    failure, `KeyboardInterrupt` included, becomes a status with a message. The frame stays within the
    limits the parent derives from the call's budget (`frame_limits`).
    """
    limits = frame_limits(request.budget, record=request.record, max_frame=max_frame)
    max_frame = limits.max_bytes
    compat_events.drain()
    recorder.begin_call(request.seed, record=request.record, budget=request.budget)
    result = _outcome(module, request, submission, max_frame, recorder, name)
    episodes = recorder.finish_call()
    if recorder.exceeded is not None and result["status"] not in ("missing_function", "bad_signature"):
        result = _status(
            "episode_limit", _budget_message(request.function, recorder), wall_time=result["wall_time"]
        )
    elif result["status"] == "ok" and recorder.overflowed:
        result = _status(
            "output_too_large",
            f"{request.function}() took more than {recorder.max_recorded_steps} environment steps while the grader records episodes; "  # noqa: E501
            "play fewer episodes",
            wall_time=result["wall_time"],
        )
    if result["status"] == "ok":
        try:
            block = log_block(episodes) if episodes else NO_EPISODES
            result["episodes"] = encode_value(block, "the episode log", max_bytes=max_frame)
        except InvalidValueError as error:
            result = _status("invalid_value", error.message, wall_time=result["wall_time"])
        except FrameTooLargeError as error:
            result = _status(
                "output_too_large",
                f"the episodes {request.function}() played need about {error.size} bytes, more than the limit of {error.limit} bytes; "  # noqa: E501
                "play fewer episodes",
                wall_time=result["wall_time"],
            )
        except MemoryError:
            result = _status(
                "memory_limit",
                "the episode log of the call does not fit in memory",
                wall_time=result["wall_time"],
            )
    result["compat_events"] = [
        {
            "kind": str(event.kind)[:100],
            "env_id": str(event.env_id)[:200],
            "detail": str(event.detail)[:MAX_EVENT_DETAIL],
        }
        for event in compat_events.drain()[:MAX_COMPAT_EVENTS]
    ]
    return _payload(result, request, limits)


def _budget_message(function: str, recorder: Recorder) -> str:
    budget = recorder.budget
    if budget is None:  # only a call with a budget can exceed it
        return ""
    played = f"{recorder.played:,} game" + ("" if recorder.played == 1 else "s")
    if recorder.exceeded == "episodes":
        return (
            f"{function}() played {played} in one call (it reset its environment {recorder.resets:,} times); "
            f"the grader records at most {budget.max_episodes:,} resets per call of {function}()"
        )
    return (
        f"{function}() took {recorder.steps:,} environment steps in one call (over {played}); "
        f"the grader records at most {budget.max_steps:,} steps per call of {function}()"
    )


def _outcome(
    module: ModuleType,
    request: CallRequest,
    submission: Path,
    max_frame: int,
    recorder: Recorder,
    shown: str | None = None,
) -> dict[str, Any]:
    name = request.function
    function = functools.partial(run_cells, module) if name == RUN_CELLS else vars(module).get(name)
    if function is None:
        return _status(
            "missing_function",
            f"your file defines no function named `{name}`; "
            f'define `def {name}(...):` at the top level of the file (not inside another function or an `if __name__ == "__main__":` block)',  # noqa: E501
        )
    if not callable(function):
        return _status(
            "missing_function",
            f"`{name}` in your file is a {type(function).__name__}, not a function; "
            f"define `def {name}(...):`",
        )
    mismatch = _signature_mismatch(name, function, request)
    stub = stub_body(function)
    # A stub that raises NotImplementedError and accepts the call is called: it says so itself.
    if stub is not None and (mismatch or stub != RAISING_STUB):
        return _status(
            "missing_function",
            f"`{name}` is still the template's stub (its body {stub}): not attempted yet. "
            f"Replace the body of `def {name}` with your solution.",
        )
    if mismatch:
        return _status("bad_signature", mismatch)
    _name_envs(recorder, request)
    namespace = vars(module)
    replaced = {provided: namespace[provided] for provided in request.provided if provided in namespace}
    namespace.update({provided: PROVIDED[provided] for provided in request.provided})
    try:
        attempt = _attempt(function, request, as_objects=False)
        if (
            attempt.error is not None
            and not isinstance(attempt.error, MemoryError)
            and _fell_on_the_name(request, recorder)
        ):
            first, error = attempt, attempt.error
            recorder.begin_call(request.seed, record=request.record, budget=request.budget)
            _name_envs(recorder, request)
            attempt = _attempt(function, request, as_objects=True)
            if attempt.error is not None and not (recorder.resets or recorder.steps):
                attempt = first  # the object got no further than the name: the name's error stands
                recorder.begin_call(request.seed, record=request.record, budget=request.budget)
            else:
                _report_object_form(name, request, error)
    finally:
        for provided in request.provided:
            if provided in replaced:
                namespace[provided] = replaced[provided]
            else:
                namespace.pop(provided, None)
    if attempt.status is not None:
        return attempt.status
    if isinstance(attempt.error, MemoryError):
        return _status(
            "memory_limit",
            f"{name}() ran out of memory (it used more than the grader allows)",
            wall_time=attempt.wall_time,
        )
    if attempt.error is not None:
        return _status(
            "exception",
            f"{name}() raised {describe_exception(attempt.error)}",
            traceback=student_traceback(attempt.error, submission, shown),
            wall_time=attempt.wall_time,
        )
    value, wall_time = attempt.value, attempt.wall_time
    try:
        encoded = encode_value(value, f"the value returned by {name}()", max_bytes=max_frame)
    except InvalidValueError as error:
        return _status("invalid_value", error.message, wall_time=wall_time)
    except FrameTooLargeError as error:
        return _status(
            "output_too_large",
            f"{name}() returned about {error.size} bytes of data, more than the limit of {error.limit} bytes; "  # noqa: E501
            "return less data",
            wall_time=wall_time,
        )
    except MemoryError:
        return _status(
            "memory_limit", f"{name}() returned more data than fits in memory", wall_time=wall_time
        )
    return {**_status("ok", ""), "value": encoded, "wall_time": wall_time}


@dataclass
class _Attempt:
    """One call of the student's function: its value, or the exception it raised, or a ready status."""

    value: Any = None
    error: BaseException | None = None
    wall_time: float = 0.0
    status: dict[str, Any] | None = None


def _attempt(function: Any, request: CallRequest, *, as_objects: bool) -> _Attempt:
    """Call `function` with the request's arguments (env arguments as names, or as objects)."""
    try:
        args = [_passed(arg, as_objects) for arg in request.args]
        kwargs = {key: _passed(arg, as_objects) for key, arg in request.kwargs.items()}
    except Exception as error:  # the grader's own env could not be made: not the student's doing
        return _Attempt(
            status=_status(
                "sandbox_error",
                f"the grader could not make the environment it passes to {request.function}(): {error}",
            )
        )
    started = time.perf_counter()
    try:
        value = function(*args, **kwargs)
    except SystemExit:
        raise
    except BaseException as error:  # KeyboardInterrupt or a BaseException subclass raised by the student
        return _Attempt(error=error, wall_time=time.perf_counter() - started)
    return _Attempt(value=value, wall_time=time.perf_counter() - started)


def _env_arguments(request: CallRequest) -> list[EnvArgument]:
    return [arg for arg in (*request.args, *request.kwargs.values()) if type(arg) is EnvArgument]


def _name_envs(recorder: Recorder, request: CallRequest) -> None:
    """Tell the recorder the names the call passes: an env made by one gets the argument's time limit."""
    for argument in _env_arguments(request):
        if argument.form in (ENV_NAME, ENV_NAME_OR_OBJECT):
            target = resolve_env_id(argument.env_id)
            recorder.named_envs[argument.env_id] = argument.max_episode_steps
            recorder.named_envs[target.gymnasium_id] = argument.max_episode_steps


def _fell_on_the_name(request: CallRequest, recorder: Recorder) -> bool:
    """Whether the call may be made again with env objects: it passed a name it may replace, and failed
    before making an env by that name, resetting or stepping any env."""
    replaceable = any(argument.form == ENV_NAME_OR_OBJECT for argument in _env_arguments(request))
    return replaceable and not (recorder.made_by_name or recorder.resets or recorder.steps)


def _report_object_form(name: str, request: CallRequest, error: BaseException) -> None:
    for argument in _env_arguments(request):
        if argument.form == ENV_NAME_OR_OBJECT:
            compat_events.record(
                compat_events.ENV_OBJECT_PASSED,
                argument.env_id,
                f"{name}() was called with the environment's name {argument.env_id!r}, as the template's `env = gym.make(env)` expects, and raised {describe_exception(error)} before making or playing it; "  # noqa: E501
                f"it was called again with an environment object, gym.make({argument.env_id!r})",
            )


def _passed(argument: Any, as_objects: bool) -> Any:
    """What the function receives for one argument: an `EnvArgument` as its name or as an env object, an
    `MdpArgument` as a fresh table (so a call that changes `P` leaves the next call's untouched)."""
    if type(argument) is MdpArgument:
        return argument.as_table()
    if type(argument) is not EnvArgument:
        return argument
    if argument.form in (ENV_NAME, ENV_NAME_OR_OBJECT) and not as_objects:
        return argument.env_id
    return _made(argument)


def _made(argument: Any) -> Any:
    """An `EnvArgument` made into an env (through the recorder, like any env of the call), else itself.

    A lab id gymnasium no longer registers is resolved quietly: the student did not name it.
    """
    if type(argument) is not EnvArgument:
        return argument
    register_envs()
    target = resolve_env_id(argument.env_id)
    env = gymnasium.make(
        target.gymnasium_id,
        max_episode_steps=argument.max_episode_steps,
        **target.merged_kwargs(dict(argument.kwargs)),
    )
    if isinstance(env, RecordingEnv):
        env.passed_by_grader = True
    return ClassicEnv(env, argument.env_id) if argument.form == ENV_GYM_OBJECT else env


def _signature_mismatch(name: str, function: Any, request: CallRequest) -> str:
    try:
        signature = inspect.signature(function)
    except Exception:  # not inspectable (a builtin, or an object whose __signature__ fails): call it anyway
        return ""
    try:
        signature.bind(*request.args, **request.kwargs)
    except TypeError as error:
        arguments = [repr(arg) for arg in request.args] + [
            f"{key}={value!r}" for key, value in request.kwargs.items()
        ]
        call = f"{name}({', '.join(arguments)})"
        return (
            f"the grader calls {call[:200]} but your function is defined as {name}{signature} ({error}); "
            f"change its parameters to accept that call"
        )
    return ""


def _status(status: str, message: str, *, traceback: str = "", wall_time: float = 0.0) -> dict[str, Any]:
    return {
        "status": status,
        "value": None,
        "message": shortened(message),
        "traceback": shortened(traceback),
        "episodes": NO_EPISODES,
        "wall_time": wall_time,
    }


def _payload(result: dict[str, Any], request: CallRequest, limits: FrameLimits) -> bytes:
    frame = {"type": "result", "id": request.call_id, "nonce": request.nonce, **result}
    payload = json.dumps(frame, allow_nan=False, separators=(",", ":")).encode()
    excess = limits.excess(payload)
    if not excess:
        return payload
    value = json.dumps(result["value"], separators=(",", ":")).encode()
    culprit = (
        "its return value"
        if limits.excess(value) or len(value) > limits.max_bytes // 2
        else "the episode log"
    )
    small = {
        **_status(
            "output_too_large",
            f"{request.function}() produced too much data ({excess.removeprefix('a ')}); "
            f"{culprit} is too large: return less data or play fewer episodes",
            wall_time=result["wall_time"],
        ),
        "compat_events": result["compat_events"][:20],
    }
    return json.dumps(
        {"type": "result", "id": request.call_id, "nonce": request.nonce, **small}, separators=(",", ":")
    ).encode()
