"""The niced child process that grades one submission: request on stdin, JSON lines on its protocol pipe.

Run as ``python -m api.jobs.child``. The parent writes one JSON request to stdin: among its fields the
file's ``path`` (under a safe grading name, ``api.uploads.grading_file_name``) and ``name``, the name its
messages and report show when that differs (the upload's or the download's; the grader's ``name``).
Messages go out on the original standard output, one JSON object per line:
``{"kind": "progress", "problem": {...}}`` as problems finish, then ``{"kind": "report", "report": {...}}``
or ``{"kind": "error", "message": ...}``. File descriptor 1 itself is pointed at standard error first, so
nothing the grader or its children print can corrupt the protocol.
"""

from __future__ import annotations

import ctypes
import json
import os
import signal
import sys
from pathlib import Path
from types import FrameType
from typing import IO, Any

from api.errors import ServiceError
from api.grader_adapter import ImportedGrader

_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """Stop this process and everything it started when the worker that started it dies (e.g. kill -9).

    Linux sends SIGTERM when the parent dies; the handler kills this process group (the worker started
    this process as a group leader), so grading processes are not left running for nobody.
    """
    signal.signal(signal.SIGTERM, _kill_own_group)
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):
        return
    if os.getppid() == 1:
        _kill_own_group(signal.SIGTERM, None)


def _kill_own_group(_signum: int, _frame: FrameType | None) -> None:
    if os.getpgid(0) == os.getpid():  # only a group of our own: never the group of whoever started us
        os.killpg(0, signal.SIGKILL)
    os._exit(1)


def _send(channel: IO[str], message: dict[str, Any]) -> None:
    channel.write(json.dumps(message) + "\n")
    channel.flush()


def main() -> int:
    """Grade the submission described on stdin; always report an outcome on the protocol pipe."""
    channel = os.fdopen(os.dup(1), "w", encoding="utf-8")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    _die_with_parent()
    request = json.loads(sys.stdin.read())
    os.nice(int(request["nice"]))
    grader = ImportedGrader(
        target=request["grader"],
        workers=request["workers"],
        allow_weak_isolation=request["allow_weak_isolation"],
    )
    try:
        path = Path(request["path"])
        config = Path(request["config"]) if request.get("config") else None
        if config is None:
            config = _edition_config(request.get("edition"), request.get("lab"))
        report = grader(
            path,
            seed=int(request["seed"]),
            on_progress=lambda problem: _send(channel, {"kind": "progress", "problem": problem}),
            only=request.get("only"),
            config=config,
            name=request.get("name"),
        )
    except ServiceError as error:
        _send(channel, {"kind": "error", "message": str(error)})
        return 1
    except Exception as error:  # the grader's own failure becomes the job's stored failure reason
        _send(channel, {"kind": "error", "message": f"the grader failed: {type(error).__name__}: {error}"})
        return 1
    _send(channel, {"kind": "report", "report": report})
    return 0


def _edition_config(edition: str | None, lab: str | None = None) -> Path | None:
    """The configuration of the edition every upload is graded as: the service's `GYMGRADE_EDITION` (of
    `GYMGRADE_LAB`), else `GYMGRADE_LAB`'s current edition, else the first edition; never detected from the
    upload (a student does not choose what they are graded on). None:
    the bundled (first edition's) one. Which edition and why goes to the job's stderr log; the report tells a
    file written for another edition's problems so."""
    from grader.lab.editions.choice import service_edition  # the grader is heavy: import it only here

    choice = service_edition(edition, lab)
    print(choice.lab_line, file=sys.stderr, flush=True)
    print(choice.line, file=sys.stderr, flush=True)
    return choice.config


if __name__ == "__main__":
    sys.exit(main())
