"""The API contract check: schemathesis, run as a client would run it, against a live `gymgrade serve`.

Used by tests/api/test_contract.py and by bench/contract.py (which records its figures), so both run the
same server configuration with the same schemathesis settings (``schemathesis.toml`` beside this file).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from api_testing import FAKE_GRADER, INSTRUCTOR_TOKEN, TESTS_DIR
from live_server import LiveProcess, create_student, service_environment

SCHEMATHESIS_CONFIG = Path(__file__).with_name("schemathesis.toml")
SCHEMATHESIS_TIMEOUT_SECONDS = 600
PHASES = ("examples", "coverage", "fuzzing", "stateful")
CONTRACT_SERVER_SETTINGS = {
    # One grading worker running the fake grader, and at most this many uploads a minute for the one
    # student: every upload schemathesis gets accepted is graded, cheaply, and there are few of them.
    "workers": 1,
    "rate_limit_per_minute": 10,
    "max_upload_bytes": 4096,
}


@dataclass(frozen=True)
class ContractRun:
    """One schemathesis run: what its JSON report counts, and its console output for a failure message."""

    caller: str
    cases: int
    failures: int
    errors: int
    phases: dict[str, str]
    seconds: float
    exit_code: int
    output: str

    @property
    def clean(self) -> bool:
        """True when every phase ran and nothing was found."""
        return (
            self.exit_code == 0
            and self.failures == 0
            and self.errors == 0
            and all(self.phases.get(phase) == "success" for phase in PHASES)
        )


def start_contract_server(directory: Path) -> LiveProcess:
    """Start `gymgrade serve` on loopback with the fake grader and the settings above."""
    env = service_environment(directory / "data", FAKE_GRADER, **CONTRACT_SERVER_SETTINGS)
    # The server's grading children import the fake grader from here (the project stays first if it is
    # on PYTHONPATH, as when a work tree is tested against an installed copy).
    paths = [*filter(None, env.get("PYTHONPATH", "").split(os.pathsep)), str(TESTS_DIR)]
    env["PYTHONPATH"] = os.pathsep.join(paths)
    return LiveProcess("serve", env, directory / "server.log").start()


def caller_tokens(server: LiveProcess) -> dict[str, str]:
    """The bearer tokens schemathesis runs with: a student's (made here) and the instructor's."""
    return {"student": create_student(server.url, "schemathesis"), "instructor": INSTRUCTOR_TOKEN}


def run_schemathesis(base_url: str, caller: str, token: str, report: Path) -> ContractRun:
    """Run ``schemathesis run --checks all`` (every phase, stateful included) as ``caller``.

    Args:
        base_url: The live service.
        caller: Who the token belongs to (for messages).
        token: Sent as ``Authorization: Bearer <token>`` with every request.
        report: Where schemathesis writes its JSON report.

    Returns:
        The counts of the report and the console output.
    """
    command = [
        str(Path(sys.executable).with_name("schemathesis")),
        "--config-file",
        str(SCHEMATHESIS_CONFIG),
        "--no-color",
        "run",
        f"{base_url}/openapi.json",
        "--checks",
        "all",
        "--phases",
        ",".join(PHASES),
        "--header",
        f"Authorization: Bearer {token}",
        "--report",
        "json",
        "--report-json-path",
        str(report),
    ]
    started = time.monotonic()
    finished = subprocess.run(
        command, capture_output=True, text=True, timeout=SCHEMATHESIS_TIMEOUT_SECONDS, check=False
    )
    seconds = time.monotonic() - started
    output = finished.stdout + finished.stderr
    if not report.exists():
        raise RuntimeError(f"schemathesis wrote no report (exit {finished.returncode}):\n{output}")
    summary = json.loads(report.read_text(encoding="utf-8"))
    return ContractRun(
        caller=caller,
        cases=summary["test_cases"]["generated"],
        failures=summary["test_cases"]["with_failures"],
        errors=len(summary["errors"]),
        phases={name: phase["status"] for name, phase in summary["phases"].items()},
        seconds=seconds,
        exit_code=finished.returncode,
        output=output,
    )
