"""Grade submissions: validate the file, run the acceptance session (pytest-xdist), build the report."""

from __future__ import annotations

import hashlib
import os
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib.metadata import version
from pathlib import Path

import grader
from grader.config import load_config
from grader.errors import UnknownProblem
from grader.execution import problem_seed
from grader.notebook import NotebookModule, build_module, is_notebook
from grader.notebook.cells import RAN_CELLS, write_cells
from grader.plugin import CaseOutcome, GraderFailure, ProblemCase, SessionPlan
from grader.problems import ProblemId
from grader.report import FIRST_EDITION, GradingTimings, ProblemResult, ProblemRun, Report, Visibility
from grader.sandbox import IsolationPolicy
from grader.sandbox.errors import IsolationUnavailable
from grader.sandbox.isolation.scope import sandbox_scope
from grader.sandbox.runner import require_isolation
from grader.session import run_session
from grader.validation import FileVerdict, check_source


@dataclass(frozen=True)
class GradingPlan:
    """What one grading run covers: the selected problems, their points and titles."""

    problems: tuple[ProblemId, ...]
    points: dict[ProblemId, float]
    titles: dict[ProblemId, str]
    config: Path | None
    config_sha256: str = ""
    """SHA-256 of the effective assignment configuration (its validated JSON form); "" for a plan made by
    hand. A report records it, so a resumed batch knows which configuration graded a file."""
    visibility: dict[ProblemId, Visibility] = field(default_factory=dict)
    edition: str = FIRST_EDITION
    """The edition the configuration grades (its `edition`, the first when it names none)."""

    @classmethod
    def load(cls, config: Path | None, only: Sequence[str] | None) -> GradingPlan:
        """The enabled problems (restricted to ``only``) of an assignment configuration.

        Raises:
            ValueError: ``only`` names a problem that does not exist.
            grader.errors.ConfigError: The configuration is invalid.
        """
        assignment = load_config(config)
        registry = assignment.registry  # the edition's problems (the configuration names its edition)
        unknown = sorted(set(only or ()) - set(registry.ids))
        if unknown:
            raise UnknownProblem(registry.unknown_message(unknown))
        problems = tuple(
            problem
            for problem in registry.ids
            if assignment.problem(problem).enabled and (not only or problem in only)
        )
        return cls(
            problems=problems,
            points={problem: assignment.problem(problem).points for problem in problems},
            titles={problem: assignment.problem(problem).title for problem in problems},
            config=config,
            config_sha256=hashlib.sha256(assignment.model_dump_json().encode()).hexdigest(),
            visibility={problem: assignment.problem(problem).visibility for problem in problems},
            edition=assignment.edition,
        )


def default_workers() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def grade_submission(
    path: Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    only: Sequence[str] | None = None,
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL,
    on_progress: Callable[[ProblemResult], None] | None = None,
    config: Path | None = None,
) -> Report:
    """Grade one submission file.

    A file that is empty, not UTF-8, not Python or too large gets a report saying so; a student's crash,
    timeout or wrong answer is a verdict in the report. Neither raises.

    Args:
        path: The student's ``.py`` file.
        seed: Grading seed: the same bytes and seed give the same statuses, scores and measurements.
        workers: Parallel pytest-xdist workers; the machine's cores when None.
        only: Problem ids to grade; all enabled problems when None.
        policy: ``REQUIRE_FULL`` (instructors, the service) refuses to run without full isolation;
            ``ALLOW_FALLBACK`` (a student's own check) runs with what the machine offers.
        on_progress: Called with each problem's result as soon as its check finishes.
        config: Assignment configuration TOML; the bundled one when None.

    Returns:
        The report. ``report.grader_errors`` lists failures of the grader itself (the affected problems
        are marked ``error`` with a message saying it is not the student's fault).

    Raises:
        grader.sandbox.errors.IsolationUnavailable: ``REQUIRE_FULL`` and this machine cannot isolate.
        grader.errors.ConfigError: The configuration is invalid.
        ValueError: ``only`` names an unknown problem.
    """
    plan = GradingPlan.load(config, only)
    callback = (lambda _path, result: on_progress(result)) if on_progress is not None else None
    return grade_files([path], plan, seed=seed, workers=workers, policy=policy, on_result=callback)[0]


def grade_files(
    paths: Sequence[Path],
    plan: GradingPlan,
    *,
    seed: int,
    workers: int | None,
    policy: IsolationPolicy,
    on_result: Callable[[Path, ProblemResult], None] | None = None,
    on_report: Callable[[Path, Report], None] | None = None,
) -> list[Report]:
    """Grade several files in one pytest-xdist run (work spread over all workers), a report per file.

    Args:
        paths: Submission files; invalid ones are reported without running anything.
        plan: The problems to grade.
        seed: Grading seed.
        workers: Parallel workers; the machine's cores when None.
        policy: Isolation policy (see ``grade_submission``).
        on_result: Called with (file, result) as each check finishes.
        on_report: Called with (file, report) as soon as the file's last check finishes (at once for a
            file rejected without running), so a batch can keep each report the moment it exists.

    Returns:
        One report per path, in the order given.
    """
    started = time.perf_counter()
    contents = {path: _read(path) for path in paths}
    reports: dict[Path, Report] = {}
    with tempfile.TemporaryDirectory(prefix="gymgrade-modules-") as modules_dir:
        graded: dict[Path, Path] = {}
        notebooks: dict[Path, NotebookModule] = {}
        for path, data in contents.items():
            prepared = _prepare(path, data, Path(modules_dir), plan.problems)
            if isinstance(prepared, FileVerdict):
                reports[path] = _rejected_report(path, data or b"", plan, seed, prepared)
                _announce(on_result, path, reports[path].problems)
                if on_report is not None:
                    on_report(path, reports[path])
            else:
                graded[path], notebook = prepared
                if notebook is not None:
                    notebooks[path] = notebook
        original = {module: path for path, module in graded.items()}
        worker_count = min(workers or default_workers(), max(len(graded) * len(plan.problems), 1))
        runs: dict[str, list[ProblemRun]] = {}

        def finish(path: Path, runs_of_path: Sequence[ProblemRun]) -> Report:
            elapsed = time.perf_counter() - started
            report = with_notebook(
                build_report(path, contents[path] or b"", seed, runs_of_path, plan, elapsed, worker_count),
                notebooks.get(path),
            )
            reports[path] = report
            if on_report is not None:
                on_report(path, report)
            return report

        def callback(module: Path, result: ProblemResult) -> None:
            if on_result is not None:
                on_result(original.get(module, module), result)

        def collect(module: Path, runs_of_path: Sequence[ProblemRun]) -> None:
            path = original.get(module, module)
            if len(runs_of_path) == len(plan.problems) and path not in reports:
                finish(path, runs_of_path)

        if graded and plan.problems:
            runs = run_acceptance(
                list(graded.values()),
                plan,
                seed=seed,
                workers=worker_count,
                policy=policy,
                on_result=callback,
                on_runs=collect,
            )
        return [reports.get(path) or finish(path, runs.get(str(graded[path]), [])) for path in paths]


def _prepare(
    path: Path, data: bytes | None, modules_dir: Path, graded: Sequence[str]
) -> tuple[Path, NotebookModule | None] | FileVerdict:
    """The file the sandbox imports for a submission: the file itself, or the module built from a notebook."""
    if data is None or not is_notebook(path.name):
        return _file_verdict(path, data) or (path, None)
    built = build_module(data, path.name, graded)
    if isinstance(built, FileVerdict):
        return built
    module = modules_dir / f"{len(list(modules_dir.iterdir()))}" / f"{path.name}.py"
    module.parent.mkdir()
    module.write_text(built.source, encoding="utf-8")
    write_cells(module, built.cells)
    return module, built


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


def build_report(
    path: Path,
    data: bytes,
    seed: int,
    runs: Sequence[ProblemRun],
    plan: GradingPlan,
    elapsed: float,
    workers: int,
) -> Report:
    """Assemble the report of a file from its problems' runs (problems in the lab's order)."""
    by_problem = {run.result.id: run for run in runs}
    results: list[ProblemResult] = []
    errors: list[str] = []
    for problem in plan.problems:
        run = by_problem.get(problem)
        if run is None:
            detail = "the grading run ended without a result for this problem"
            run = _internal_error_run(path, problem, plan, seed, detail)
        if run.internal_error is not None:
            errors.append(f"{problem}: {run.internal_error}")
        results.append(run.result)
    isolation = next((run.isolation for run in runs if run.isolation), None)
    timings = [result.timings for result in results if result.timings is not None]
    check_seconds = sum(timing.wall_seconds for timing in timings)
    student_seconds = sum(timing.student_seconds for timing in timings)
    return Report(
        submission=path.name,
        sha256=hashlib.sha256(data).hexdigest(),
        seed=seed,
        config_sha256=plan.config_sha256,
        edition=plan.edition,
        gymnasium_version=version("gymnasium"),
        grader_version=grader.__version__,
        isolation=isolation,
        score=round(sum(result.score for result in results), 6),
        max_score=sum(result.max_score for result in results),
        problems=results,
        grader_errors=errors,
        execution_time=elapsed,
        timings=GradingTimings(
            elapsed_seconds=elapsed,
            workers=workers,
            check_seconds=check_seconds,
            student_seconds=student_seconds,
            overhead_seconds=max(check_seconds - student_seconds, 0.0),
        ),
    )


def _announce(
    on_result: Callable[[Path, ProblemResult], None] | None, path: Path, results: Sequence[ProblemResult]
) -> None:
    if on_result is not None:
        for result in results:
            on_result(path, result)


def _file_verdict(path: Path, data: bytes | None) -> FileVerdict | None:
    if data is None:
        return FileVerdict(
            "error", f"{path.name} could not be read: check that the file exists and is readable."
        )
    return check_source(data, path.name)


def _rejected_report(path: Path, data: bytes, plan: GradingPlan, seed: int, verdict: FileVerdict) -> Report:
    results = [
        ProblemResult(
            id=problem,
            title=plan.titles[problem],
            status=verdict.status,
            score=0.0,
            max_score=plan.points[problem],
            feedback=verdict.message,
            seed=problem_seed(seed, problem),
            visibility=plan.visibility.get(problem, "visible"),
        )
        for problem in plan.problems
    ]
    return Report(
        submission=path.name,
        sha256=hashlib.sha256(data).hexdigest(),
        seed=seed,
        config_sha256=plan.config_sha256,
        edition=plan.edition,
        gymnasium_version=version("gymnasium"),
        grader_version=grader.__version__,
        score=0.0,
        max_score=sum(plan.points.values()),
        submission_error=verdict.message,
        problems=results,
    )


def _internal_error_run(
    path: Path, problem: ProblemId, plan: GradingPlan, seed: int, detail: str
) -> ProblemRun:
    return ProblemRun.grader_failure(
        str(path),
        problem,
        title=plan.titles[problem],
        points=plan.points[problem],
        seed=problem_seed(seed, problem),
        detail=detail,
        visibility=plan.visibility.get(problem, "visible"),
    )


def _read(path: Path) -> bytes | None:
    try:
        return path.read_bytes()
    except OSError:
        return None


def run_acceptance(
    paths: Sequence[Path],
    plan: GradingPlan,
    *,
    seed: int,
    workers: int,
    policy: IsolationPolicy,
    on_result: Callable[[Path, ProblemResult], None] | None,
    on_runs: Callable[[Path, Sequence[ProblemRun]], None] | None = None,
) -> dict[str, list[ProblemRun]]:
    """Run the acceptance tests of valid files in one session in this process; the runs per file path.

    ``on_result`` and ``on_runs`` (a file and all its runs so far) are called in the calling thread as
    each run arrives. Problems the session ended without a result for (a worker died, pytest stopped) get
    an internal-error run.

    Raises:
        grader.sandbox.errors.IsolationUnavailable: ``REQUIRE_FULL`` and this machine cannot isolate
            (checked before anything starts, and raised after the session if a worker found it so).
    """
    if policy is IsolationPolicy.REQUIRE_FULL:
        require_isolation(policy)
    session_plan = SessionPlan(
        submissions=tuple(path.resolve() for path in paths),
        problems=plan.problems,
        seed=seed,
        policy=policy,
        config=plan.config.resolve() if plan.config is not None else None,
    )
    runs: dict[str, list[ProblemRun]] = {str(path): [] for path in paths}
    unavailable: list[str] = []

    def deliver(case: ProblemCase, outcome: CaseOutcome) -> None:
        path = paths[case.index]
        if isinstance(outcome, GraderFailure):
            if outcome.kind == "isolation_unavailable":
                unavailable.append(outcome.detail)
                return
            outcome = _internal_error_run(path, case.problem, plan, seed, outcome.detail)
        runs[str(path)].append(outcome)
        if on_result is not None:
            on_result(path, outcome.result)
        if on_runs is not None:
            on_runs(path, runs[str(path)])

    # The scope outlives the session: its harness trees, scratch dirs and cgroups go when it closes.
    with sandbox_scope() as scope:
        end = run_session(session_plan, workers=workers, on_outcome=deliver, environment=scope)
    if unavailable:
        raise IsolationUnavailable(unavailable[0])
    detail = f"the grading run stopped (pytest exit code {end.exit_code}): {end.log_tail}"
    for case in session_plan.cases():
        if case.problem not in {run.result.id for run in runs[str(paths[case.index])]}:
            deliver(case, GraderFailure(kind="grader_error", detail=detail))
    return runs
