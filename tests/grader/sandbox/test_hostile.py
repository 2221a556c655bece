"""Every hostile sample in submissions/hostile ends in its expected outcome and leaves the host unaffected."""

from __future__ import annotations

import json
import os
import secrets
import shutil
import socket
import threading
import tomllib
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from grader.sandbox import Call, CallBudget, IsolationPolicy, Limits, OutcomeStatus, Sandbox, probe_isolation
from grader.sandbox.isolation.cgroup import JOB_PREFIX
from grader.sandbox.replay import replay_episode
from grader.sandbox.text import EVENT_CHARS, MESSAGE_CHARS

ROOT = Path(__file__).resolve().parents[3]
HOSTILE = ROOT / "submissions" / "hostile"
SAMPLES: list[dict[str, Any]] = tomllib.loads((HOSTILE / "outcomes.toml").read_text())["sample"]
LIMITS = Limits(
    call_seconds=2,
    import_seconds=6,
    memory_bytes=1536 << 20,
    max_pids=32,
    output_bytes=4096,
    scratch_bytes=16 << 20,
    file_bytes=8 << 20,
)
# Host memory must come back after each sample. Processes and cgroups being gone is checked exactly; the
# host-wide MemAvailable is noisy (other jobs on the machine, other pytest-xdist workers each possibly
# running a contained memory bomb), so this check allows two memory limits plus one per other worker: it
# catches memory that stays taken on a large scale (an escaped process holding gigabytes).
OTHER_WORKERS = max(int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1")) - 1, 0)
MEMORY_SLACK = (2 + OTHER_WORKERS) * LIMITS.memory_bytes

pytestmark = [
    pytest.mark.sandbox,
    pytest.mark.skipif(
        not probe_isolation().full, reason="needs full isolation:\n" + probe_isolation().summary()
    ),
]


class LoopbackServer:
    """A TCP server on 127.0.0.1 counting the connections it accepts."""

    def __init__(self) -> None:
        self.socket = socket.create_server(("127.0.0.1", 0))
        self.port: int = self.socket.getsockname()[1]
        self.connections = 0
        self.thread = threading.Thread(target=self._accept, daemon=True)
        self.thread.start()

    def _accept(self) -> None:
        while True:
            try:
                connection, _ = self.socket.accept()
            except OSError:
                return
            self.connections += 1
            connection.close()


@pytest.fixture(scope="module")
def loopback() -> Iterator[LoopbackServer]:
    server = LoopbackServer()
    yield server
    server.socket.close()


def _memory_available() -> int:
    for line in Path("/proc/meminfo").read_text().splitlines():
        if line.startswith("MemAvailable:"):
            return int(line.split()[1]) * 1024
    raise AssertionError("no MemAvailable in /proc/meminfo")


def _processes_mentioning(token: str) -> list[str]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and int(entry.name) != os.getpid():
            try:
                command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if token in command:
                found.append(f"{entry.name}: {command[:200]}")
    return found


def _job_cgroups() -> list[Path]:
    pattern = f"{JOB_PREFIX}{os.getpid()}-*"
    return [path for path in Path("/sys/fs/cgroup").glob(f"**/{pattern}") if path.is_dir()]


def _arguments(sample: dict[str, Any], port: int, marker: str) -> tuple[Any, ...]:
    replacements = {"$port": port, "$project": str(ROOT), "$marker": marker}
    return tuple(replacements.get(argument, argument) for argument in sample.get("args", []))


def _marker_paths(marker: str) -> list[Path]:
    return [
        ROOT / marker,
        Path("/work/main") / marker,
        Path("/tmp") / marker,
        Path("/etc") / marker,
        Path("/usr") / marker,
        Path("/root") / marker,
        Path("/") / marker,
    ]


@pytest.mark.parametrize(
    "sample", SAMPLES, ids=[f"{s['file']}:{s.get('function', 'import')}" for s in SAMPLES]
)
def test_hostile_sample_gets_its_outcome_and_leaves_the_host_unaffected(
    sample: dict[str, Any], loopback: LoopbackServer, tmp_path: Path
) -> None:
    token = secrets.token_hex(6)
    submission = tmp_path / f"{Path(sample['file']).stem}_{token}.py"
    shutil.copyfile(HOSTILE / sample["file"], submission)
    marker = f"gymgrade-pwned-{token}"
    memory_before = _memory_available()
    connections_before = loopback.connections
    function = sample.get("function")

    limits = replace(LIMITS, call_seconds=sample.get("call_seconds", LIMITS.call_seconds))
    with Sandbox(submission, seed=7, limits=limits, policy=IsolationPolicy.REQUIRE_FULL) as sandbox:
        budget = CallBudget(**sample["budget"]) if "budget" in sample else None
        outcome = sandbox.call(
            Call(function or "ok", _arguments(sample, loopback.port, marker), budget=budget)
        )
        following = sandbox.call(Call("ok"))

    assert outcome.status == OutcomeStatus(sample["status"]), outcome.message + outcome.stderr[-2000:]
    assert outcome.message or outcome.status is OutcomeStatus.OK
    if "message_contains" in sample:
        assert sample["message_contains"] in outcome.message
    if "stdout_contains" in sample:
        assert sample["stdout_contains"] in outcome.stdout
        assert len(outcome.stdout) < 2 * LIMITS.output_bytes
    if "value" in sample:
        assert outcome.value == sample["value"]
        assert type(outcome.value) is type(sample["value"])
    if "value_text" in sample:
        assert sample["value_text"] in json.dumps(outcome.value, ensure_ascii=False)
    events = [event.model_dump() for event in outcome.compat_events]
    for text in (outcome.message, outcome.stdout, outcome.stderr, json.dumps(events)):
        assert "\x00" not in text
        text.encode("utf-8")  # no lone surrogate
    json.dumps(outcome.value, ensure_ascii=False).encode("utf-8")
    assert len(outcome.message) < 2 * MESSAGE_CHARS + 200
    assert all(len(text) < EVENT_CHARS + 100 for event in events for text in event.values())
    if sample.get("value_below_max_pids"):
        assert 0 < outcome.value < LIMITS.max_pids
    if sample.get("replay_mismatch"):
        assert outcome.episodes, "the patched run must have been recorded"
        assert any(replay_episode(log).mismatch for log in outcome.episodes)
    if function is None:
        assert following.status == outcome.status, "a failed import is reported for every call"
    elif sample.get("following_call", True):
        assert (following.status, following.value) == (OutcomeStatus.OK, 42), following.message

    assert sandbox.leftovers == 0
    assert _processes_mentioning(token) == []
    assert _job_cgroups() == []
    assert loopback.connections == connections_before
    assert [path for path in _marker_paths(marker) if path.exists()] == []
    memory_after = _memory_available()
    not_returned = memory_before - memory_after
    assert not_returned < MEMORY_SLACK, f"{not_returned >> 20} MiB of host memory not returned"
