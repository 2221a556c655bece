"""Live progress on a terminal: a line per finished check, or a one-line bar."""

from __future__ import annotations

import sys
from typing import TextIO

from grader.render.neutral import terminal_line
from grader.report import ProblemResult

_STATUS_MARK = {
    "passed": "PASS",
    "failed": "FAIL",
    "error": "ERROR",
    "timeout": "TIMEOUT",
    "missing": "MISSING",
    "skipped": "SKIPPED",
}


def result_line(result: ProblemResult) -> str:
    """One human line for a finished check: status, title and points."""
    mark = _STATUS_MARK.get(result.status, result.status.upper())
    points = f"{result.score:g}/{result.max_score:g}"
    return f"[{mark:>7}] {result.title} ({points})"


class ProgressBar:
    """A one-line progress bar on a terminal, or plain lines when the output is not a terminal."""

    def __init__(self, total: int, stream: TextIO | None = None, width: int = 30) -> None:
        self.total = max(total, 1)
        self.done = 0
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.interactive = self.stream.isatty()

    def advance(self, label: str) -> None:
        """Count one finished unit of work, labelled (e.g. 'alice.py: cartpole passed'); a name in the
        label that a student chose is shown as one inert line (`grader.render.neutral.terminal_line`)."""
        self.done += 1
        label = terminal_line(label)
        if self.interactive:
            filled = self.width * self.done // self.total
            bar = "#" * filled + "-" * (self.width - filled)
            self.stream.write(f"\r[{bar}] {self.done}/{self.total} {label[:60]:<60}")
            if self.done >= self.total:
                self.stream.write("\n")
        else:
            self.stream.write(f"{self.done}/{self.total} {label}\n")
        self.stream.flush()
