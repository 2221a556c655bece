"""One acceptance session in the calling process: pytest.main with pytest-xdist, outcomes through hooks.

The calling process is pytest-xdist's controller; the checks run on xdist workers (always at least one, so
a crash of the grader's own code while checking ends a worker, never the caller). `AcceptanceController`,
handed to ``pytest.main`` as a plugin object, receives each case's report in the calling thread
(``pytest_runtest_logreport``, and ``pytest_handlecrashitem`` for the case a worker died on) and hands its
typed outcome over at once. Nothing pytest prints reaches the caller's stdout or stderr: it goes to a log
whose tail explains a session that stopped early.

In detail:

- The session leaves the caller as it was: `session_environment` sets `GYMGRADE_SANDBOX_SCOPE`,
  `PYTEST_DISABLE_PLUGIN_AUTOLOAD=1`, `PYTHONDONTWRITEBYTECODE=1` and removes `PYTEST_ADDOPTS`/
  `PYTEST_PLUGINS` for the session only (workers inherit them), stops bytecode writing and restores
  `sys.path`; `-c grader/grading/cases/pytest.ini --rootdir grader/grading/cases` keep the caller's pytest
  settings out; `faulthandler`, `unraisableexception` and `threadexception` are off (process-wide
  hooks; the last one's forced garbage collection cost ~1 s per session). Everything pytest prints goes
  to a log, never to the caller's stdout or stderr (the callbacks still print normally). Sessions in
  one process run one at a time (a lock); nested inside a running pytest (the project's own tests,
  under xdist too) they work, and a batch reuses `grader.grading.cases.*` from `sys.modules`. The workers
  get the `sys.path` the calling process had when xdist was imported (xdist's rule).
- Ending: the controller SIGKILLs the workers at session finish (`stop_workers`, execnet's kill): once
  every result is in, their interpreter exit (1-2 s under load) is not waited for. A `KeyboardInterrupt`
  (Ctrl-C, or raised by a callback) stops the workers the same way and reaches the caller as
  `KeyboardInterrupt` (pytest would return `ExitCode.INTERRUPTED`), so `grade_many` raises
  `BatchInterrupted`; any other exception a callback raises is raised again after the session.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TextIO

import pytest

from grader.grading.plugin import (
    OUTCOME_PROPERTY,
    CaseOutcome,
    GraderFailure,
    ProblemCase,
    SessionPlan,
    read_outcome,
)
from grader.lab.ids import acceptance_module_name

ACCEPTANCE_DIR = Path(__file__).with_name("cases")
OutcomeCallback = Callable[[ProblemCase, CaseOutcome], None]
_PLUGINS = (
    "grader.grading.plugin",
    "xdist.plugin",
    "no:cacheprovider",
    "no:tmpdir",
    "no:faulthandler",
    "no:unraisableexception",
    "no:threadexception",
)
_BASE_ARGS = (*(argument for plugin in _PLUGINS for argument in ("-p", plugin)), "--assert=plain", "-q")
"""``--assert=plain``: no case needs pytest's assertion rewriting, whose import hook parsed every case
module again and looked at every import of the session (about 0.1 s of CPU per process of a session)."""
_SESSION_ENVIRONMENT = {"PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1", "PYTHONDONTWRITEBYTECODE": "1"}
_CALLER_SETTINGS = ("PYTEST_ADDOPTS", "PYTEST_PLUGINS")
"""Environment variables through which the caller's own pytest settings would reach the session."""
_LOG_TAIL_LINES = 5
_ONE_SESSION_AT_A_TIME = threading.Lock()


@dataclass(frozen=True)
class SessionEnd:
    """How a session ended: pytest's exit code and the last lines it printed."""

    exit_code: int
    log_tail: str


def acceptance_args(plan: SessionPlan, workers: int) -> list[str]:
    """The pytest arguments of a session (the workers rebuild their configuration from them).

    ``-c`` and ``--rootdir`` keep the caller's own pytest settings out. No case uses pytest's temporary
    directories (the sandbox makes its own in the grading's scope), so the tmpdir plugin is off too: it
    would make a directory per session under the temp dir, named by a user id that Windows lacks. The
    faulthandler, unraisableexception and threadexception plugins are off: they replace process-wide
    hooks of the calling process, and the second forces garbage collections that cost about a second per
    session.
    """
    settings = ["-c", str(ACCEPTANCE_DIR / "pytest.ini"), "--rootdir", str(ACCEPTANCE_DIR)]
    return [*case_paths(plan), *settings, *_BASE_ARGS, "-n", str(max(workers, 1)), plan.option()]


def case_paths(plan: SessionPlan) -> list[str]:
    """What a session collects: the acceptance module of each planned problem (the whole folder when none is
    planned). Every process of the session (the workers, and the controller with ``-n 0``) collects, and a
    module it collected only to deselect cost it the module's import and collection."""
    if not plan.problems:
        return [str(ACCEPTANCE_DIR)]
    return [str(ACCEPTANCE_DIR / f"{acceptance_module_name(problem)}.py") for problem in plan.problems]


def run_session(
    plan: SessionPlan,
    *,
    workers: int,
    on_outcome: OutcomeCallback,
    environment: Mapping[str, str] | None = None,
    plugins: Sequence[str] = (),
) -> SessionEnd:
    """Run the acceptance tests of ``plan`` on ``workers`` xdist workers, in this process.

    ``on_outcome`` is called in the calling thread with each case's outcome as soon as it arrives, at
    most once per case; cases without one when the session ends (it stopped early) are the caller's to
    fill in. Sessions in one process run one at a time, as pytest's state is the process's (so
    ``on_outcome`` must not start another).

    Args:
        plan: The cases to grade.
        workers: xdist workers (at least one is started).
        on_outcome: Receives (case, outcome).
        environment: Variables the workers must inherit (set in ``os.environ`` for the session only).
        plugins: Further pytest plugin modules for the controller and every worker (test doubles).

    Raises:
        KeyboardInterrupt: The session was interrupted (Ctrl-C).
        BaseException: Whatever ``on_outcome`` raised, once the session's workers are stopped.
    """
    controller = AcceptanceController(plan, on_outcome, sys.stdout, sys.stderr)
    args = acceptance_args(plan, workers)
    for name in plugins:
        args += ["-p", name]
    with (
        _ONE_SESSION_AT_A_TIME,
        session_environment(environment or {}),
        tempfile.TemporaryFile("w+", encoding="utf-8", errors="replace") as log,
    ):
        with contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
            exit_code = pytest.main(args, plugins=[controller])
        if controller.abandoned is not None:
            raise controller.abandoned
        if exit_code == pytest.ExitCode.INTERRUPTED or controller.interrupted:
            raise KeyboardInterrupt
        return SessionEnd(int(exit_code), _tail(log))


@contextlib.contextmanager
def session_environment(variables: Mapping[str, str]) -> Iterator[None]:
    """``variables`` and the session's own settings in ``os.environ``, the caller's pytest settings out of
    it, no bytecode written; ``os.environ``, ``sys.path`` and bytecode writing restored on exit."""
    changes: dict[str, str | None] = {**_SESSION_ENVIRONMENT, **variables}
    changes.update(dict.fromkeys(_CALLER_SETTINGS))
    saved = {name: os.environ.get(name) for name in changes}
    saved_path, saved_bytecode = list(sys.path), sys.dont_write_bytecode
    _set_environment(changes)
    sys.dont_write_bytecode = True
    try:
        yield
    finally:
        _set_environment(saved)
        sys.path[:] = saved_path
        sys.dont_write_bytecode = saved_bytecode


def _set_environment(values: Mapping[str, str | None]) -> None:
    for name, value in values.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value


class AcceptanceController:
    """The controller's plugin object: hands each expected case's outcome over as its report arrives.

    Reports are matched to cases by the node ids the plan generated (`ProblemCase.node_id`); any other
    report (slots, an unexpected id) is ignored, and a case's first outcome is its outcome.
    """

    def __init__(
        self, plan: SessionPlan, on_outcome: OutcomeCallback, stdout: TextIO, stderr: TextIO
    ) -> None:
        self.expected = {case.node_id: case for case in plan.cases()}
        self.delivered: set[str] = set()
        self.on_outcome = on_outcome
        self.streams = (stdout, stderr)
        self.abandoned: BaseException | None = None
        """What ``on_outcome`` raised, to be raised again once the session has ended."""
        self.interrupted = False

    @property
    def complete(self) -> bool:
        """Whether every expected case has its outcome."""
        return len(self.delivered) == len(self.expected)

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        case = self.expected.get(report.nodeid)
        if case is None or report.nodeid in self.delivered:
            return
        carried = dict(report.user_properties).get(OUTCOME_PROPERTY)
        if carried is not None:
            self._deliver(case, read_outcome(carried))
        elif report.failed:
            lines = report.longreprtext.strip().splitlines() or ["the check failed without a message"]
            self._deliver(case, GraderFailure(kind="grader_error", detail=lines[-1]))

    @pytest.hookimpl(optionalhook=True)
    def pytest_handlecrashitem(self, crashitem: str, report: pytest.TestReport) -> None:
        case = self.expected.get(crashitem)
        if case is not None and crashitem not in self.delivered:
            last_line = report.longreprtext.strip().splitlines()[-1:] or [crashitem]
            detail = f"the grading worker crashed while checking this problem ({last_line[0]})"
            self._deliver(case, GraderFailure(kind="grader_error", detail=detail))

    def pytest_keyboard_interrupt(self) -> None:
        self.interrupted = True

    @pytest.hookimpl(tryfirst=True)
    def pytest_sessionfinish(self, session: pytest.Session) -> None:
        """Stop the workers at once: whatever they still do (an interpreter's exit takes a second or two,
        an abandoned check longer) is not wanted once the session is over."""
        stop_workers(session.config)

    def _deliver(self, case: ProblemCase, outcome: CaseOutcome) -> None:
        self.delivered.add(case.node_id)
        stdout, stderr = self.streams
        try:
            with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
                self.on_outcome(case, outcome)
        except BaseException as error:
            self.abandoned = error
            raise


def stop_workers(config: pytest.Config) -> None:
    """SIGKILL every xdist worker of a session (execnet's own kill, with no grace period)."""
    dsession = config.pluginmanager.getplugin("dsession")
    nodemanager = getattr(dsession, "nodemanager", None)
    if nodemanager is not None:
        nodemanager.group.terminate(timeout=0)


def _tail(log: IO[str]) -> str:
    log.seek(0)
    lines = [line.strip() for line in log.read().splitlines() if line.strip()]
    return " | ".join(lines[-_LOG_TAIL_LINES:])
