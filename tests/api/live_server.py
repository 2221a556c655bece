"""End-to-end helpers: `gymgrade serve` or `gymgrade worker` as a real process, and an HTTP client."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import httpx
from api_testing import INSTRUCTOR_TOKEN, free_port, instructor_headers

START_TIMEOUT_SECONDS = 60.0
REAL_GRADER = "grader.grading.grade:grade_submission"
E2E_GRADER = REAL_GRADER
"""The grader behind the end-to-end, browser and restart tests: the real one."""
PARTIAL_SOLUTION = (Path(__file__).with_name("data") / "partial_solution.py").read_bytes()
PARTIAL_STATUSES = {
    "random_blackjack": "passed",
    "blackjack": "missing",
    "cartpole": "passed",
    "car": "passed",
    "taxi": "missing",
    "find_qvalues": "skipped",  # worth 0 points: not called (issue 11)
}
SYNTAX_ERROR = b"def random_blackjack(n):\n    return (\n"
GRADING_WAIT_SECONDS = 300.0


def create_student(base_url: str, name: str) -> str:
    """Create a student over HTTP and return their token."""
    response = httpx.post(base_url + "/students", json={"name": name}, headers=instructor_headers())
    response.raise_for_status()
    token: str = response.json()["token"]
    return token


def upload(base_url: str, token: str, content: bytes, name: str = "opengym.py") -> int:
    """Upload a file over HTTP and return the submission id."""
    response = httpx.post(
        base_url + "/submissions",
        files={"file": (name, content)},
        headers={"Authorization": f"Bearer {token}"},
    )
    if response.status_code != 202:
        raise RuntimeError(f"upload refused: {response.status_code} {response.text}")
    submission_id: int = response.json()["id"]
    return submission_id


def wait_for(
    base_url: str, token: str, submission_id: int, statuses: set[str], timeout: float = GRADING_WAIT_SECONDS
) -> dict[str, Any]:
    """Poll a submission until its status is one of ``statuses``."""
    deadline = time.monotonic() + timeout
    while True:
        view: dict[str, Any] = httpx.get(
            f"{base_url}/submissions/{submission_id}",
            headers={"Authorization": f"Bearer {token}"},
            timeout=10,
        ).json()
        if view["status"] in statuses or time.monotonic() > deadline:
            return view
        time.sleep(0.1)


def service_environment(data_dir: Path, grader: str, **settings: Any) -> dict[str, str]:
    """The environment of a service process: this one's, plus GYMGRADE_* settings for a test."""
    env = {name: value for name, value in os.environ.items() if not name.startswith("GYMGRADE_")}
    env.update(
        {
            "GYMGRADE_DATA_DIR": str(data_dir),
            "GYMGRADE_INSTRUCTOR_TOKEN": INSTRUCTOR_TOKEN,
            "GYMGRADE_GRADER": grader,
            "GYMGRADE_POLL_SECONDS": "0.1",
        }
    )
    env.update({f"GYMGRADE_{name.upper()}": str(value) for name, value in settings.items()})
    return env


class LiveProcess:
    """A service process (its own session, output in a log file) that can be killed with SIGKILL.

    Args:
        command: ``serve`` or ``worker``.
        env: The process environment (see :func:`service_environment`).
        log: Where its output goes.
        port: The port for ``serve`` (a free one when None).
    """

    def __init__(self, command: str, env: dict[str, str], log: Path, port: int | None = None) -> None:
        self.port = port or free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        arguments = (
            ["serve", "--host", "127.0.0.1", "--port", str(self.port)] if command == "serve" else [command]
        )
        self._argv = [str(Path(sys.executable).with_name("gymgrade")), *arguments]
        self._env = env
        self._log_path = log
        self.process: subprocess.Popen[bytes] | None = None

    def start(self, wait_for_http: bool = True) -> LiveProcess:
        """Start the process and, for ``serve``, wait until /healthz answers."""
        with self._log_path.open("ab") as log:
            self.process = subprocess.Popen(
                self._argv, env=self._env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True
            )
        if wait_for_http:
            self._wait_until_healthy()
        return self

    def _wait_until_healthy(self) -> None:
        deadline = time.monotonic() + START_TIMEOUT_SECONDS
        while time.monotonic() < deadline:
            if self.process is not None and self.process.poll() is not None:
                raise RuntimeError(f"the service exited with {self.process.returncode}:\n{self.log()}")
            try:
                if httpx.get(self.url + "/healthz", timeout=1.0).status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            time.sleep(0.1)
        raise RuntimeError(f"the service did not answer within {START_TIMEOUT_SECONDS} s:\n{self.log()}")

    def kill(self) -> None:
        """SIGKILL the service process only (as a crash would), and reap it."""
        if self.process is not None and self.process.poll() is None:
            self.process.send_signal(signal.SIGKILL)
            self.process.wait()

    def stop(self) -> None:
        """Ask the process to stop (SIGTERM), then kill its whole process group if it lingers."""
        if self.process is None:
            return
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.process.pid, signal.SIGKILL)

    def log(self) -> str:
        """The process's output so far."""
        return self._log_path.read_text(encoding="utf-8", errors="replace")[-5000:]
