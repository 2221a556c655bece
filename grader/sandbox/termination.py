"""How a child that sent no result ended, as a status and a message a student understands."""

from __future__ import annotations

import signal
from dataclasses import dataclass

from grader.sandbox.host import signal_number
from grader.sandbox.isolation.bubblewrap import without_new_root
from grader.sandbox.isolation.cgroup import JOIN_FAILED_EXIT
from grader.sandbox.limits import Limits
from grader.sandbox.outcome import OutcomeStatus
from grader.sandbox.process import ChildProcess

_SIGNAL_BASE = 128
"""bubblewrap exits with 128 + N when the child was killed by signal N."""


@dataclass
class Ending:
    """A status with its message (and, for a failed import, the output the import printed)."""

    status: OutcomeStatus
    message: str
    stdout: str = ""
    stderr: str = ""


def forged_message(detail: str) -> str:
    """The message for data on the result channel that the harness did not send."""
    return (
        f"the result channel carried data the harness did not send ({detail}); "
        "do not write to the grader's file descriptors or imitate its messages: "
        "return your result from the function"
    )


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def _during(function: str | None) -> str:
    return f"{function}()" if function is not None else "importing your file"


def classify_exit(child: ChildProcess, function: str | None, limits: Limits) -> Ending:
    """Classifies a child that closed its result channel without a result.

    Args:
        child: The child (its main process is waited for briefly, then the tree is killed).
        function: The function being called, or None while the submission was being imported.
        limits: The limits in force (named in messages).
    """
    code = child.wait_exit()
    if code is None:
        child.kill_tree()
        return Ending(
            OutcomeStatus.INVALID_VALUE,
            forged_message(f"{_during(function)} closed the grader's result channel"),
        )
    if child.oom_killed():
        return Ending(
            OutcomeStatus.MEMORY_LIMIT,
            f"{_during(function)} used more than {limits.memory_bytes // (1 << 20)} MiB of memory and was stopped; "  # noqa: E501
            "use less memory (smaller arrays, fewer stored episodes)",
        )
    uses_signal_codes = child.launch.signals_in_exit_status
    number = -code if code < 0 else 0
    if uses_signal_codes and _SIGNAL_BASE < code < _SIGNAL_BASE + 64:
        number = code - _SIGNAL_BASE
    if function is None and code in (1, JOIN_FAILED_EXIT) and _looks_like_sandbox_failure(child):
        return Ending(
            OutcomeStatus.SANDBOX_ERROR,
            f"the sandbox failed to start ({_start_failure(child)}); "
            "this is not your fault: tell the instructor (`gymgrade doctor` shows the sandbox's binds and layers on this machine)",  # noqa: E501
        )
    if number and number == signal_number("SIGXCPU"):
        return Ending(
            OutcomeStatus.TIMEOUT,
            f"{_during(function)} used more than {limits.cpu_seconds} seconds of CPU time and was stopped",
        )
    if number:
        if number == signal_number("SIGKILL") and child.launch.cgroup is None:
            hint = " (possibly for using too much memory)"
        else:
            hint = ""
        return Ending(
            OutcomeStatus.KILLED,
            f"{_during(function)} was killed by {_signal_name(number)}{hint}; "
            "a signal ended the process before it returned",
        )
    what = "your file" if function is None else f"{function}()"
    where = "while being imported" if function is None else "before returning"
    fix = (
        'move that code under `if __name__ == "__main__":`'
        if function is None
        else "return a value instead of calling sys.exit(), exit() or os._exit()"
    )
    return Ending(
        OutcomeStatus.EXITED,
        f"{what} ended the process with exit status {code} {where} (sys.exit(), exit() or os._exit()); {fix}",
    )


_START_FAILURE_CHARS = 300


def _start_failure(child: ChildProcess) -> str:
    """The wrapper's first line (bwrap names the path and the reason), as the host names the path."""
    lines = child.stderr.head.decode("utf-8", errors="replace").strip().splitlines() or ["no message"]
    first = lines[0] if lines[0].startswith(("bwrap:", "gymgrade-join:", "setpriv:")) else lines[-1]
    return without_new_root(first)[:_START_FAILURE_CHARS]


def _looks_like_sandbox_failure(child: ChildProcess) -> bool:
    text = child.stderr.head.decode("utf-8", errors="replace")
    started_badly = "Traceback" in text and "bootstrap.py" in text
    return text.startswith(("bwrap:", "gymgrade-join:", "setpriv:")) or started_badly
