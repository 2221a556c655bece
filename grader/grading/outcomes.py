"""The one place a grading's outcomes arrive: each case's outcome in, each file's report out, as they finish.

The acceptance session hands every case's outcome to `Outcomes.receive` the moment its report arrives;
the collector keeps the runs of each file, tells its `GradingListener` each problem's result (progress) and,
once a file's last problem is in, builds that file's report and hands it over (so a batch writes it at
once). A file refused before anything ran, and the cases a session ended without, go through the same
collector, so every report of a grading is built in one place (`build_report`).

In detail:

- **One collector** (`grader/grading/outcomes.py`): outcomes are typed: an acceptance test attaches
  `grader.grading.plugin.CaseOutcome = ProblemRun | GraderFailure(kind: "isolation_unavailable" |
  "grader_error", detail)` as JSON to its report (`user_properties`); the controller reads it in
  `pytest_runtest_logreport` and turns a worker that died on a case into a `grader_error` for exactly that
  case in `pytest_handlecrashitem` (the others still arrive; xdist replaces the worker). A case's first
  outcome goes, in the calling thread, to `Outcomes.receive`, which keeps each file's runs, tells the caller's
  `GradingListener` the result (`result(path, result)`: progress) and, with the file's last problem, builds
  its report (`build_report`, `with_notebook`) and hands it over (`report(path, report)`). Files refused
  before running (`Outcomes.reject`) and cases a session ended without (`Outcomes.close`: "the grading run
  stopped (pytest exit code N): <the last lines pytest printed>") go through the same collector.
  `IsolationUnavailable` fails closed before the session (`grader.sandbox.runner.require_isolation`, the check
  `Sandbox` makes too) and is raised by `close` when a worker reported it. A batch's listener is its
  `OutputDirectory` (writes the report, passes the result on to the progress bar); `grade_submission`'s is
  `OnResult(on_progress)`.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path
from typing import Any, Protocol

import grader
from grader.grading.execution import problem_seed
from grader.grading.plan import GradingPlan
from grader.grading.plugin import CaseOutcome, GraderFailure, ProblemCase
from grader.lab.registry import ProblemId
from grader.report import GradingTimings, ProblemResult, ProblemRun, Report
from grader.sandbox.errors import IsolationUnavailable
from grader.submission.notebook import NotebookModule
from grader.submission.notebook.cells import RAN_CELLS
from grader.submission.validation import FileVerdict

NO_RESULT = "the grading run ended without a result for this problem"


class GradingListener(Protocol):
    """Hears a grading as it goes (both methods run in the grading's calling thread)."""

    def result(self, path: Path, result: ProblemResult) -> None:
        """A problem of ``path`` is graded (progress)."""
        ...

    def report(self, path: Path, report: Report) -> None:
        """Every problem of ``path`` is graded: its report, final."""
        ...


class Silent:
    """A listener that keeps nothing (a grading whose caller only wants the returned reports)."""

    def result(self, path: Path, result: ProblemResult) -> None:
        """Ignore a result."""

    def report(self, path: Path, report: Report) -> None:
        """Ignore a report."""


@dataclass(frozen=True)
class OnResult:
    """A listener that passes each result to a function (a progress display); reports are returned."""

    function: Callable[[Path, ProblemResult], None]

    def result(self, path: Path, result: ProblemResult) -> None:
        """Pass a result on."""
        self.function(path, result)

    def report(self, path: Path, report: Report) -> None:
        """Nothing: the grading returns its reports."""


@dataclass(frozen=True)
class Submission:
    """A file of the grading: its bytes, the module the sandbox imports, and its notebook if it is one."""

    path: Path
    data: bytes
    module: Path
    notebook: NotebookModule | None = None
    edition_note: str | None = None
    name: str = ""
    """The file's own name as shown to a person (`grade_files`' ``names``); ``path.name`` when empty."""


class Outcomes:
    """Receives a grading's outcomes; builds each file's report the moment its last problem arrives.

    Args:
        plan: The grading's plan (problems, points, titles, visibility, configuration digest).
        seed: The grading seed.
        workers: The workers the session runs on (recorded in each report's timings).
        listener: Hears each result and each report as they come.
        started: When the grading started (`time.perf_counter()`; now when None): each report's elapsed
            time counts from it.
    """

    def __init__(
        self,
        plan: GradingPlan,
        *,
        seed: int,
        workers: int,
        listener: GradingListener,
        started: float | None = None,
    ) -> None:
        self.plan = plan
        self.seed = seed
        self.workers = workers
        self.listener = listener
        self.started = time.perf_counter() if started is None else started
        self.graded: list[Submission] = []
        self.runs: dict[Path, dict[ProblemId, ProblemRun]] = {}
        self.reports: dict[Path, Report] = {}
        self.unavailable: list[str] = []

    def reject(self, path: Path, data: bytes, verdict: FileVerdict, name: str = "") -> None:
        """A file refused before anything ran (unreadable, empty, not Python, too large): its report now
        (``name``: the file's own name as shown, ``path.name`` when empty)."""
        results = [
            ProblemResult(
                id=problem,
                title=self.plan.titles[problem],
                status=verdict.status,
                score=0.0,
                max_score=self.plan.points[problem],
                feedback=verdict.message,
                seed=problem_seed(self.seed, problem),
                visibility=self.plan.visibility[problem],
            )
            for problem in self.plan.problems
        ]
        report = build_report(
            path, data, self.seed, self.plan, results, name=name, submission_error=verdict.message
        )
        for result in results:
            self.listener.result(path, result)
        self._finish(path, report)

    def expect(self, submission: Submission) -> None:
        """A file whose problems the session grades (its index in the session's plan is its place here)."""
        self.graded.append(submission)
        self.runs[submission.path] = {}

    def receive(self, case: ProblemCase, outcome: CaseOutcome) -> None:
        """A case's outcome, as the session hands it over (at most once per case)."""
        submission = self.graded[case.index]
        if isinstance(outcome, GraderFailure):
            if outcome.kind == "isolation_unavailable":
                self.unavailable.append(outcome.detail)
                return
            outcome = self._grader_failure(submission.path, case.problem, outcome.detail)
        runs = self.runs[submission.path]
        runs[case.problem] = outcome
        self.listener.result(submission.path, outcome.result)
        if len(runs) == len(self.plan.problems):
            self._finish(submission.path, self._build(submission))

    def close(self, detail: str = NO_RESULT) -> None:
        """The session is over: every case still without an outcome is the grader's failure (``detail``).

        Raises:
            grader.sandbox.errors.IsolationUnavailable: A worker found that this machine cannot isolate.
        """
        if self.unavailable:
            raise IsolationUnavailable(self.unavailable[0])
        failure = GraderFailure(kind="grader_error", detail=detail)
        for index, submission in enumerate(self.graded):
            for problem in self.plan.problems:
                if problem not in self.runs[submission.path]:
                    self.receive(ProblemCase(index, submission.module, problem), failure)
            if submission.path not in self.reports:  # a plan without problems
                self._finish(submission.path, self._build(submission))

    def reports_of(self, paths: Sequence[Path]) -> list[Report]:
        """The reports of ``paths``, in that order (after `close`)."""
        return [self.reports[path] for path in paths]

    def _finish(self, path: Path, report: Report) -> None:
        self.reports[path] = report
        self.listener.report(path, report)

    def _grader_failure(self, path: Path, problem: ProblemId, detail: str) -> ProblemRun:
        return ProblemRun.grader_failure(
            str(path),
            problem,
            title=self.plan.titles[problem],
            points=self.plan.points[problem],
            seed=problem_seed(self.seed, problem),
            detail=detail,
            visibility=self.plan.visibility[problem],
        )

    def _build(self, submission: Submission) -> Report:
        runs = [self.runs[submission.path][problem] for problem in self.plan.problems]
        results = [run.result for run in runs]
        timings = [result.timings for result in results if result.timings is not None]
        check_seconds = sum(timing.wall_seconds for timing in timings)
        student_seconds = sum(timing.student_seconds for timing in timings)
        elapsed = time.perf_counter() - self.started
        report = build_report(
            submission.path,
            submission.data,
            self.seed,
            self.plan,
            results,
            name=submission.name,
            isolation=next((run.isolation for run in runs if run.isolation), None),
            edition_note=submission.edition_note,
            grader_errors=[
                f"{run.result.id}: {run.internal_error}" for run in runs if run.internal_error is not None
            ],
            execution_time=elapsed,
            timings=GradingTimings(
                elapsed_seconds=elapsed,
                workers=self.workers,
                check_seconds=check_seconds,
                student_seconds=student_seconds,
                overhead_seconds=max(check_seconds - student_seconds, 0.0),
            ),
        )
        return with_notebook(report, submission.notebook)


def build_report(
    path: Path,
    data: bytes,
    seed: int,
    plan: GradingPlan,
    results: Sequence[ProblemResult],
    *,
    name: str = "",
    **grading: Any,
) -> Report:
    """The report of a file from its problems' results (in the plan's order): what every report states of
    the file, the grading and the grader, the score, and ``grading``'s further fields of `Report`
    (``isolation``, ``grader_errors``, ``timings``, ``submission_error``, ...). ``name`` is the file's own
    name as shown (a class's download names it, its copy on disk may be numbered); ``path.name`` if empty."""
    return Report(
        submission=name or path.name,
        sha256=hashlib.sha256(data).hexdigest(),
        seed=seed,
        config_sha256=plan.config_sha256,
        lab=plan.assignment.lab,
        edition=plan.edition,
        gymnasium_version=version("gymnasium"),
        grader_version=grader.__version__,
        score=round(sum(result.score for result in results), 6),
        max_score=sum(result.max_score for result in results),
        problems=list(results),
        **grading,
    )


def with_notebook(report: Report, notebook: NotebookModule | None) -> Report:
    """The report of a notebook: its summary attached, each problem told about the globals it lacks, and
    tracebacks pointing at the notebook's cells rather than at the module built from them."""
    if notebook is None:
        return report
    module_name = f"{report.submission}.py"
    problems = [
        result.model_copy(
            update={
                "feedback": notebook.cited(
                    " ".join([*_global_notes(notebook, result), result.feedback]), module_name
                ),
                "output": notebook.cited(result.output, module_name),
            }
        )
        for result in report.problems
    ]
    return report.model_copy(update={"notebook": notebook.summary, "problems": problems})


def _global_notes(notebook: NotebookModule, result: ProblemResult) -> list[str]:
    """The notes on globals only skipped statements set: none for a problem not run, or run after the
    notebook's cells (which set them)."""
    if result.status == "skipped" or result.measurements.get(RAN_CELLS):
        return []
    return notebook.summary.notes_for(result.id)
