"""Tests of grader/grading/session.py: one acceptance session in this process, outcomes through hooks.

Every session here grades files whose functions are missing, so a check takes a sandbox start and no
student time. These tests themselves run under pytest (and pytest-xdist): each session is nested.
"""

from __future__ import annotations

import faulthandler
import os
import re
import signal
import sys
import threading
import time
from pathlib import Path

import pytest
import xdist.workermanage
from faulty_worker import CRASH_CASE, NO_ISOLATION

from grader.grading.plan import GradingPlan
from grader.grading.plugin import CaseOutcome, GraderFailure, ProblemCase, SessionPlan
from grader.grading.session import run_session
from grader.report import ProblemRun
from grader.sandbox import IsolationPolicy

pytestmark = pytest.mark.slow  # each test runs a nested pytest-xdist session

ENDLESS = "def car():\n    while True:\n        pass\n"


def _plan(tmp_path: Path, *problems: str, submissions: int = 1, source: str = "import math\n") -> SessionPlan:
    paths = []
    for index in range(submissions):
        path = tmp_path / f"student_{index}.py"
        path.write_text(source)
        paths.append(path)
    return SessionPlan(
        grading=GradingPlan.load(None, problems),
        submissions=tuple(paths),
        seed=0,
        policy=IsolationPolicy.ALLOW_FALLBACK,
    )


@pytest.fixture
def faulty_workers(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The plugins that make the session's workers load the `faulty_worker` double.

    xdist workers get the sys.path the controller had when xdist was imported (here: before pytest put
    this directory on it), so the double's directory is added to that copy for this test.
    """
    frozen: list[str] = xdist.workermanage._sys_path
    monkeypatch.setattr(xdist.workermanage, "_sys_path", [str(Path(__file__).resolve().parents[1]), *frozen])
    return ["faulty_worker"]


HANG_SECONDS = 300
"""Bounds a hang only: waits poll for an event and end as soon as it happens."""


def _children(parent: int | None = None) -> set[int]:
    """Live processes whose parent is `parent` (this process by default)."""
    parent = os.getpid() if parent is None else parent
    found = set()
    for entry in Path("/proc").iterdir():
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, ValueError):
            continue
        if fields[0] != "Z" and int(fields[1]) == parent:
            found.add(int(entry.name))
    return found


def _gone(pids: set[int]) -> bool:
    deadline = time.monotonic() + HANG_SECONDS
    while pids & _children() and time.monotonic() < deadline:
        time.sleep(0.1)
    return not pids & _children()


def test_every_case_arrives_through_the_hooks_once(tmp_path: Path) -> None:
    plan = _plan(tmp_path, "car", "cartpole", submissions=2)
    received: list[tuple[str, CaseOutcome]] = []
    end = run_session(
        plan, workers=2, on_outcome=lambda case, outcome: received.append((case.node_id, outcome))
    )
    assert end.exit_code == 0
    assert sorted(node_id for node_id, _ in received) == sorted(case.node_id for case in plan.cases())
    for _, outcome in received:
        assert isinstance(outcome, ProblemRun) and outcome.result.status == "missing"


def test_a_worker_that_dies_mid_check_fails_that_case_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, faulty_workers: list[str]
) -> None:
    plan = _plan(tmp_path, "car", "cartpole", submissions=2)
    crashed = ProblemCase(1, plan.submissions[1], "car")
    monkeypatch.setenv(CRASH_CASE, crashed.node_id)
    received: dict[str, CaseOutcome] = {}

    def receive(case: ProblemCase, outcome: CaseOutcome) -> None:
        received[case.node_id] = outcome

    run_session(plan, workers=2, on_outcome=receive, plugins=faulty_workers)
    failure = received.pop(crashed.node_id)
    assert isinstance(failure, GraderFailure) and failure.kind == "grader_error"
    assert re.fullmatch(
        rf"the grading worker crashed while checking this problem \(worker 'gw\d+' crashed while running "
        rf"'{re.escape(crashed.node_id)}'\)",
        failure.detail,
    )
    assert sorted(received) == sorted(case.node_id for case in plan.cases() if case != crashed)
    assert all(isinstance(outcome, ProblemRun) for outcome in received.values())


def test_isolation_unavailable_on_a_worker_is_a_typed_outcome(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, faulty_workers: list[str]
) -> None:
    monkeypatch.setenv(NO_ISOLATION, "1")
    received: list[CaseOutcome] = []
    run_session(
        _plan(tmp_path, "car"),
        workers=1,
        on_outcome=lambda _case, outcome: received.append(outcome),
        plugins=faulty_workers,
    )
    assert received == [
        GraderFailure(kind="isolation_unavailable", detail="test double: this worker cannot isolate")
    ]


def test_an_outcome_callback_that_raises_ends_the_session_and_its_workers(tmp_path: Path) -> None:
    plan = _plan(tmp_path, "car", "cartpole", submissions=2)
    workers: set[int] = set()
    before = _children()  # processes earlier tests of this run left as children (servers, fixtures)

    def give_up(case: ProblemCase, outcome: CaseOutcome) -> None:
        workers.update(_children() - before)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_session(plan, workers=2, on_outcome=give_up)
    assert workers, "the session's xdist workers are children of this process"
    assert _gone(workers), "the workers must be stopped when the session is abandoned"


@pytest.mark.alone(
    "sends SIGINT to its own process: a KeyboardInterrupt escaping there would end an xdist worker, and "
    "xdist ends the whole run on a worker's Ctrl-C; run last, alone, it can cost no other test"
)
def test_ctrl_c_during_a_session_reaches_the_caller(tmp_path: Path) -> None:
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("Ctrl-C does not raise KeyboardInterrupt in this process")
    plan = _plan(tmp_path, "car", source=ENDLESS)
    workers: set[int] = set()
    before = _children()  # processes earlier tests of this run left as children (servers, fixtures)

    pressed, session_over, hung = threading.Event(), threading.Event(), threading.Event()

    def press_ctrl_c_once_the_check_runs() -> None:
        # The event: a worker has started the student's child, which loops forever.
        deadline = time.monotonic() + HANG_SECONDS
        while not any(_children(worker) for worker in _children() - before) and time.monotonic() < deadline:
            time.sleep(0.1)
        workers.update(_children() - before)
        pressed.set()
        os.kill(os.getpid(), signal.SIGINT)
        # Bounds a hang only: a session that waited for its endless check would never return.
        if not session_over.wait(HANG_SECONDS):
            hung.set()
            for worker in workers & _children():
                os.kill(worker, signal.SIGKILL)

    watcher = threading.Thread(target=press_ctrl_c_once_the_check_runs, daemon=True)
    watcher.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_session(plan, workers=1, on_outcome=lambda case, outcome: None)
    finally:
        session_over.set()
    watcher.join()
    assert pressed.is_set() and not hung.is_set(), (
        "an interrupted session must not wait for its endless check"
    )
    assert workers and _gone(workers), "no worker may outlive the interrupted session"


def test_nested_sessions_leave_the_calling_pytest_as_it_was(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, environment = list(sys.path), dict(os.environ)
    bytecode, fault_handler = sys.dont_write_bytecode, faulthandler.is_enabled()
    received: list[CaseOutcome] = []
    for _ in range(2):  # a batch: several sessions in one process reuse grader.grading.cases.* modules
        run_session(
            _plan(tmp_path, "car"), workers=1, on_outcome=lambda _case, outcome: received.append(outcome)
        )
    assert [type(outcome) for outcome in received] == [ProblemRun, ProblemRun]
    assert (sys.path, dict(os.environ)) == (path, environment)
    assert (sys.dont_write_bytecode, faulthandler.is_enabled()) == (bytecode, fault_handler)
    print("still captured")
    assert capsys.readouterr() == ("still captured\n", "")
    with pytest.raises(AssertionError, match=r"assert 2 == 3"):  # this module's asserts are still rewritten
        assert len(received) == 3


def test_nothing_reaches_the_callers_stdout_or_stderr(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    printed: list[str] = []

    def show(case: ProblemCase, outcome: CaseOutcome) -> None:
        print(f"progress {case.problem}")  # the caller's own output still reaches its stdout
        printed.append(case.problem)

    run_session(_plan(tmp_path, "car", "cartpole"), workers=2, on_outcome=show)
    captured = capfd.readouterr()
    assert captured.out == "".join(f"progress {problem}\n" for problem in printed)
    assert captured.err == ""
