"""Drive the child harness in a plain subprocess (no isolation) over the real protocol, for unit tests."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import grader
from grader.sandbox.child import frames

HARNESS = Path(grader.__file__).resolve().parent / "sandbox" / "child" / "__main__.py"


class ChildClient:
    """One harness process importing `submission`; `call` sends a call frame and returns the result frame."""

    def __init__(self, submission: Path, *, seed: int = 0, extra_args: tuple[str, ...] = ()) -> None:
        requests_read, self._requests = os.pipe()
        results_write_read = os.pipe()
        self._results = os.fdopen(results_write_read[0], "rb")
        self._output = tempfile.TemporaryFile()  # noqa: SIM115 (closed in __exit__)
        self._errors = tempfile.TemporaryFile()  # noqa: SIM115
        self.process = subprocess.Popen(
            [
                sys.executable,
                "-I",
                "-B",
                str(HARNESS),
                "--submission",
                str(submission),
                "--requests",
                str(requests_read),
                "--results",
                str(results_write_read[1]),
                "--seed",
                str(seed),
                *extra_args,
            ],
            pass_fds=(requests_read, results_write_read[1]),
            stdin=subprocess.DEVNULL,
            stdout=self._output,
            stderr=self._errors,
            cwd=submission.parent,
        )
        os.close(requests_read)
        os.close(results_write_read[1])
        self.first_frame = self.read()
        self._next_id = 0

    def read(self) -> dict[str, Any] | None:
        """The next frame on the result channel, None at its end."""
        return frames.read_frame(self._results)

    def call(
        self,
        function: str,
        *args: Any,
        seed: int = 1,
        record: bool = True,
        budget: dict[str, int] | None = None,
        **kwargs: Any,
    ) -> dict[str, Any] | None:
        """Send one call; return the result frame (None if the child ended without one)."""
        self._next_id += 1
        frame = {
            "type": "call",
            "id": self._next_id,
            "nonce": f"n{self._next_id}",
            "function": function,
            "args": frames.encode_value(list(args)),
            "kwargs": frames.encode_value(kwargs),
            "seed": seed,
            "record": record,
            "budget": budget,
        }
        try:
            frames.write_frame(self._requests, frame)
        except BrokenPipeError:
            return None
        return self.read()

    def close(self) -> int:
        """End the child (closing its request channel) and return its exit status."""
        with contextlib.suppress(OSError):
            os.close(self._requests)
        status = self.process.wait(timeout=30)
        self._results.close()
        return status

    def output(self) -> tuple[str, str]:
        """The child's stdout and stderr so far."""
        texts = []
        for stream in (self._output, self._errors):
            stream.seek(0)
            texts.append(stream.read().decode(errors="replace"))
        return texts[0], texts[1]

    def __enter__(self) -> ChildClient:
        return self

    def __exit__(self, *exc_info: object) -> None:
        if self.process.poll() is None:
            self.close()
        self._output.close()
        self._errors.close()


def write_submission(directory: Path, source: str, name: str = "submission.py") -> Path:
    """Write `source` as a submission file and return its path."""
    path = directory / name
    path.write_text(source)
    return path
