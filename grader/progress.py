"""Live progress: follow the results file as checks finish, and show it on a terminal."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TextIO

from grader.report import ProblemResult, ProblemRun

_STATUS_MARK = {
    "passed": "PASS",
    "failed": "FAIL",
    "error": "ERROR",
    "timeout": "TIMEOUT",
    "missing": "MISSING",
    "skipped": "SKIPPED",
}


class ResultsFollower:
    """Reads the complete lines appended to a JSON-lines results file since the last poll."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._offset = 0
        self._partial = b""

    def poll(self) -> list[ProblemRun]:
        """The results written since the previous call (an unfinished last line waits for the next)."""
        try:
            with self.path.open("rb") as stream:
                stream.seek(self._offset)
                chunk = stream.read()
        except FileNotFoundError:
            return []
        self._offset += len(chunk)
        lines = (self._partial + chunk).split(b"\n")
        self._partial = lines.pop()
        return [ProblemRun.model_validate_json(line) for line in lines if line.strip()]


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
        """Count one finished unit of work, labelled (e.g. 'alice.py: cartpole passed')."""
        self.done += 1
        if self.interactive:
            filled = self.width * self.done // self.total
            bar = "#" * filled + "-" * (self.width - filled)
            self.stream.write(f"\r[{bar}] {self.done}/{self.total} {label[:60]:<60}")
            if self.done >= self.total:
                self.stream.write("\n")
        else:
            self.stream.write(f"{self.done}/{self.total} {label}\n")
        self.stream.flush()
