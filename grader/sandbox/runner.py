"""`Sandbox`: one isolated child importing a submission once and serving many calls; `run_calls`."""

from __future__ import annotations

import re
import secrets
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from types import TracebackType
from typing import Any

from grader.sandbox.child.budget import FrameLimits, WireBudget, frame_limits
from grader.sandbox.child.errors import InvalidEpisodeLogError, InvalidValueError, ProtocolError
from grader.sandbox.child.frames import decode_value, encode_frame, encode_value, parse_payload
from grader.sandbox.child.seeding import derive_call_seed
from grader.sandbox.episode_log import EpisodeLog, episodes_from_plain
from grader.sandbox.errors import IsolationUnavailable, SandboxClosedError
from grader.sandbox.isolation import probe_isolation
from grader.sandbox.isolation.launch import build_launch
from grader.sandbox.isolation.layer import IsolationReport
from grader.sandbox.limits import IsolationPolicy, Limits
from grader.sandbox.messages import ImportErrorMessage, ResultMessage, first_message, result_message
from grader.sandbox.outcome import IMPORT_TIMEOUT, Call, CallOutcome, FunctionInfo, OutcomeStatus
from grader.sandbox.process import ChildProcess, FrameEnd, FrameWait
from grader.sandbox.termination import Ending, classify_exit, forged_message
from grader.sandbox.text import clean_plain

READY_FRAME_LIMITS = FrameLimits(max_bytes=16 << 20, max_nodes=200_000)
"""The `ready` frame lists at most `MAX_LISTED_NAMES` names of `MAX_LISTED_PARAMETERS` parameters each."""
IMPORT_SEED_INDEX = 2**31
"""`derive_call_seed(seed, IMPORT_SEED_INDEX)` seeds randomness while the submission is imported."""


def _unavailable_message(report: IsolationReport) -> str:
    lines = [f"- {layer.name}: {layer.detail}; to fix: {layer.remedy}" for layer in report.missing]
    return (
        "full isolation is required to run untrusted submissions, but these layers are missing:\n"
        + "\n".join(lines)
        + "\n"
        "Install what is missing, or (only for your own code) pass IsolationPolicy.ALLOW_FALLBACK (`gymgrade check` does; `gymgrade grade --allow-weak-isolation`)."  # noqa: E501
    )


def require_isolation(policy: IsolationPolicy, isolation: IsolationReport | None = None) -> IsolationReport:
    """The isolation to apply: `isolation`, else every layer this machine offers (probed once per process).

    Raises:
        IsolationUnavailable: `policy` is REQUIRE_FULL and a required layer is missing.
    """
    report = isolation if isolation is not None else probe_isolation()
    if policy is IsolationPolicy.REQUIRE_FULL and not report.full:
        raise IsolationUnavailable(_unavailable_message(report))
    return report


def sandbox_file_name(name: str) -> str:
    """What the sandbox calls its copy of a file named ``name`` (and so its messages, without a shown name):
    every character outside ``[A-Za-z0-9_.-]`` made ``_``, ending in ``.py``."""
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "submission.py"
    return safe if safe.endswith(".py") else f"{safe}.py"


class Sandbox:
    """One child process that imports the submission once and serves calls in order.

    A fatal outcome (timeout, memory limit, killed, exited, forged frames) ends the child; the next call
    starts a fresh one. Each call's seed depends only on the sandbox seed and the call's index, so a
    restart does not change later calls. Use as a context manager, or call `close`.

    Attributes:
        isolation: The layers of isolation protecting the children.
    """

    def __init__(
        self,
        submission: Path,
        *,
        seed: int,
        limits: Limits | None = None,
        policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL,
        isolation: IsolationReport | None = None,
        shown_name: str = "",
    ) -> None:
        """Prepares the sandbox (the child starts with the first call or `functions`).

        Args:
            submission: The student's file (read once, now).
            seed: The grading seed; every call's seed is derived from it and the call's index.
            limits: Resource limits (defaults: `Limits()`).
            policy: Whether missing isolation layers are refused (`REQUIRE_FULL`) or reported.
            isolation: The layers to apply, from `probe_isolation(disable=...)` (default: every layer
                this machine offers).
            shown_name: The file's own name in the child's messages (a class's zip is graded from numbered
                copies); plain data, never a path. The submission's file name when empty.

        Raises:
            IsolationUnavailable: `policy` is REQUIRE_FULL and a required layer is missing.
            OSError: the submission cannot be read.
        """
        self.isolation = require_isolation(policy, isolation)
        self.seed = seed
        self.limits = limits or Limits()
        self._source = submission.read_bytes()
        self._name = sandbox_file_name(submission.name)
        self._shown_name = shown_name
        self._next_index = 0
        self._child: ChildProcess | None = None
        self._functions: dict[str, FunctionInfo] = {}
        self._import_failure: Ending | None = None
        self._closed = False
        self.leftovers = 0
        """Children whose process tree could not be fully removed (should stay 0)."""

    def __enter__(self) -> Sandbox:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.close()

    @property
    def functions(self) -> Mapping[str, FunctionInfo]:
        """The submission's top-level names with their signatures (empty when it cannot be imported)."""
        self._ensure_child()
        return dict(self._functions)

    def close(self) -> None:
        """Ends the child and removes its cgroup and scratch."""
        self._stop_child()
        self._closed = True

    def call(self, call: Call) -> CallOutcome:
        """Runs one call in the child and classifies how it ended.

        Raises:
            SandboxClosedError: the sandbox was closed.
            ValueError: the call's arguments are not plain data.
        """
        if self._closed:
            raise SandboxClosedError("this Sandbox is closed; open a new one to make more calls")
        index = self._next_index
        self._next_index += 1
        seed = derive_call_seed(self.seed, index)
        try:
            arguments = encode_value(list(call.args), "the call's arguments")
            keywords = encode_value(dict(call.kwargs), "the call's keyword arguments")
        except InvalidValueError as error:
            raise ValueError(error.message) from None
        child = self._ensure_child()
        if child is None:
            failure = self._import_failure or Ending(OutcomeStatus.SANDBOX_ERROR, "the child did not start")
            return self._outcome(call, seed, failure, stdout=failure.stdout, stderr=failure.stderr)
        nonce = secrets.token_hex(16)
        budget = None if call.budget is None else WireBudget(call.budget.max_episodes, call.budget.max_steps)
        frame_limit = frame_limits(budget, record=call.record_episodes, max_frame=self.limits.frame_bytes)
        request = {
            "type": "call",
            "id": index,
            "nonce": nonce,
            "function": call.function,
            "args": arguments,
            "kwargs": keywords,
            "seed": seed,
            "record": call.record_episodes,
            "budget": None if budget is None else budget.to_plain(),
            "provided": list(call.provided),
        }
        child.reset_oom_baseline()
        started = time.perf_counter()
        seconds = self.limits.call_seconds if call.seconds is None else call.seconds
        sent = child.send(encode_frame(request, self.limits.frame_bytes), seconds)
        if sent is FrameEnd.FRAME:
            remaining = seconds - (time.perf_counter() - started)
            wait = child.wait_frame(remaining, frame_limit.max_bytes)
        else:
            wait = FrameWait(sent)
        if wait.end is FrameEnd.FRAME and child.oom_killed():
            ending = Ending(
                OutcomeStatus.MEMORY_LIMIT,
                f"a process started by {call.function}() used more than {self.limits.memory_bytes >> 20} MiB of memory together with the others and was stopped; "  # noqa: E501
                "use less memory",
            )
            return self._fatal(call, seed, started, ending)
        if wait.end is FrameEnd.FRAME:
            return self._result(call, seed, started, wait.payload, index, nonce, frame_limit)
        if wait.end is FrameEnd.TIMEOUT:
            child.kill_tree()
            ending = Ending(
                OutcomeStatus.TIMEOUT,
                f"{call.function}() did not return within {seconds:g} seconds",
            )
        elif wait.end is FrameEnd.TOO_LARGE:  # the harness reports oversized results in a small frame
            child.kill_tree()
            ending = _forged(
                f"a frame announced {wait.size:,} bytes, more than this call's limit of {frame_limit.max_bytes:,} bytes"  # noqa: E501
            )
        elif wait.end is FrameEnd.EXTRA_DATA:
            child.kill_tree()
            ending = _forged("more than one result frame arrived")
        else:
            ending = classify_exit(child, call.function, self.limits)
        return self._fatal(call, seed, started, ending)

    def _result(
        self,
        call: Call,
        seed: int,
        started: float,
        payload: bytes,
        index: int,
        nonce: str,
        frame_limit: FrameLimits,
    ) -> CallOutcome:
        elapsed = time.perf_counter() - started
        child = self._child
        message = _result_message(payload, frame_limit, index, nonce)
        if isinstance(message, str):
            return self._fatal(call, seed, started, _forged(message))
        status = message.outcome_status
        value: Any = None
        episodes: list[EpisodeLog] = []
        if status is OutcomeStatus.OK:
            try:
                value = clean_plain(decode_value(message.value, f"the value returned by {call.function}()"))
                episodes = episodes_from_plain(message.episodes, call.budget)
            except (InvalidValueError, InvalidEpisodeLogError) as error:
                return self._fatal(call, seed, started, _forged(str(error)))
        return CallOutcome(
            call=call,
            status=status,
            value=value,
            episodes=episodes,
            compat_events=message.compat_events,
            stdout=child.stdout.take() if child else "",
            stderr=child.stderr.take() if child else "",
            message=message.explanation(),
            wall_time=min(message.wall_time, elapsed),
            seed=seed,
        )

    def _fatal(self, call: Call, seed: int, started: float, ending: Ending) -> CallOutcome:
        child = self._child
        stdout = child.stdout.take() if child is not None else ""
        stderr = child.stderr.take() if child is not None else ""
        self._stop_child()
        return self._outcome(
            call, seed, ending, stdout=stdout, stderr=stderr, wall_time=time.perf_counter() - started
        )

    def _outcome(
        self, call: Call, seed: int, ending: Ending, *, stdout: str, stderr: str, wall_time: float = 0.0
    ) -> CallOutcome:
        return CallOutcome(
            call=call,
            status=ending.status,
            value=None,
            episodes=[],
            compat_events=[],
            stdout=stdout,
            stderr=stderr,
            message=ending.message,
            wall_time=wall_time,
            seed=seed,
        )

    def _ensure_child(self) -> ChildProcess | None:
        if self._child is not None or self._import_failure is not None:
            return self._child
        limits = self.limits

        def make_launch(requests_fd: int, results_fd: int) -> Any:
            return build_launch(
                self.isolation,
                limits,
                submission=self._source,
                submission_name=self._name,
                requests_fd=requests_fd,
                results_fd=results_fd,
                import_seed=derive_call_seed(self.seed, IMPORT_SEED_INDEX),
                shown_name=self._shown_name,
            )

        try:
            child = ChildProcess.start(make_launch, limits.output_bytes)
        except OSError as error:
            self._import_failure = Ending(
                OutcomeStatus.SANDBOX_ERROR, f"the sandbox could not start: {error}"
            )
            return None
        self._child = child
        ending = self._await_ready(child)
        if ending is not None:
            ending.stdout, ending.stderr = child.stdout.take(), child.stderr.take()
            self._import_failure = ending
            self._stop_child()
        return self._child

    def _await_ready(self, child: ChildProcess) -> Ending | None:
        wait = child.wait_frame(self.limits.import_seconds, READY_FRAME_LIMITS.max_bytes)
        if wait.end is FrameEnd.TIMEOUT:
            child.kill_tree()
            return Ending(
                OutcomeStatus.TIMEOUT,
                f"{IMPORT_TIMEOUT} {self.limits.import_seconds:g} seconds; "
                'move long-running code into functions or under `if __name__ == "__main__":`',
            )
        if wait.end is FrameEnd.CLOSED:
            return classify_exit(child, None, self.limits)
        if wait.end is not FrameEnd.FRAME:
            child.kill_tree()
            return Ending(OutcomeStatus.INVALID_VALUE, forged_message("the first frame was malformed"))
        try:
            message = READY_FRAME_LIMITS.excess(wait.payload) or first_message(parse_payload(wait.payload))
        except ProtocolError as error:
            message = str(error)
        if isinstance(message, str):
            child.kill_tree()
            return Ending(OutcomeStatus.INVALID_VALUE, forged_message(message))
        if isinstance(message, ImportErrorMessage):
            return Ending(OutcomeStatus.IMPORT_ERROR, message.explanation())
        self._functions = message.function_table()
        return None

    def _stop_child(self) -> None:
        child, self._child = self._child, None
        if child is not None and not child.close():
            self.leftovers += 1


def _result_message(payload: bytes, frame_limit: FrameLimits, index: int, nonce: str) -> ResultMessage | str:
    """The result frame answering request `index`, or why it is forged."""
    # Sized and counted before any Python object is built: a forged frame costs what an honest may.
    problem = frame_limit.excess(payload)
    if problem:
        return problem
    try:
        message = result_message(parse_payload(payload))
    except ProtocolError as error:
        return str(error)
    if not isinstance(message, str) and (message.id != index or message.nonce != nonce):
        return "a result frame answered a different request"
    return message


def _forged(detail: str) -> Ending:
    return Ending(OutcomeStatus.INVALID_VALUE, forged_message(detail))


def run_calls(
    submission: Path,
    calls: Iterable[Call],
    *,
    seed: int,
    limits: Limits | None = None,
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL,
) -> list[CallOutcome]:
    """Runs `calls` in order in one `Sandbox` and returns their outcomes (same order).

    Raises:
        IsolationUnavailable: `policy` is REQUIRE_FULL and a required layer is missing.
    """
    with Sandbox(submission, seed=seed, limits=limits, policy=policy) as sandbox:
        return [sandbox.call(call) for call in calls]
