"""Grade submissions: from the files to their reports, top to bottom.

`grade_files` reads each file (a notebook is turned into the module the sandbox imports, a file that cannot
be graded is refused with its report at once), runs one acceptance session over every (file, problem) case
on pytest-xdist workers (`grader.grading.session`), and hands each case's outcome to one `Outcomes`, which
builds each file's report the moment its last problem is graded and tells the caller's `GradingListener`.

Its contract:

- Each file is read once, without following links (`grader/submission/untrusted_file.py`, `read_untrusted`:
  opened with `O_NOFOLLOW` where the system has it, else `lstat` before and `fstat` after; a hard link, a
  FIFO, a folder is refused; read from the descriptor, at most `grading.READ_LIMIT` + 1 bytes), and the
  sandbox imports a copy of those bytes in the grading's own temporary folder (or the module built from a
  notebook), never the student's path again: a file swapped or linked in meanwhile, or a `<name>.cells.json`
  planted beside it, is not what is graded.
- Invalid files (a link, empty, not UTF-8, not Python, > 1 MB) return a `Report` with clear verdicts
  (`report.submission_error`), never raise; a student's crash or timeout is a verdict. It raises only
  `IsolationUnavailable` (`REQUIRE_FULL` on a machine that cannot isolate), `ConfigError` and `ValueError` (an
  unknown id in `only`). A failure of the grader itself marks the problem `error` and is listed in
  `report.grader_errors` (the service treats a non-empty list as a failed job). `config` is an assignment TOML
  (default `grader/lab/assignment.toml`), `plan` one loaded already (then `config` and `only` are not read).
  `on_progress` is called from the calling thread.
- Deterministic: `report.graded_view()` (everything but `execution_time` and `timings`) is identical for
  the same bytes and seed.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from grader import parsing
from grader.grading.outcomes import GradingListener, OnResult, Outcomes, Silent, Submission
from grader.grading.plan import GradingPlan
from grader.grading.plugin import SessionPlan
from grader.grading.session import run_session
from grader.lab.editions import EDITIONS
from grader.lab.editions.detection import detect_source, edition_note
from grader.report import ProblemResult, Report
from grader.sandbox import IsolationPolicy
from grader.sandbox.host import usable_cpus
from grader.sandbox.isolation.scope import sandbox_scope
from grader.sandbox.runner import require_isolation, sandbox_file_name
from grader.submission.notebook import MAX_NOTEBOOK_BYTES, NotebookModule, build_module, is_notebook
from grader.submission.notebook.bounded import build_script
from grader.submission.notebook.cells import write_cells
from grader.submission.notebook.script import defines_only, may_be_export
from grader.submission.untrusted_file import UnsafeFile, read_untrusted
from grader.submission.validation import MAX_SUBMISSION_BYTES, FileVerdict, check_source

READ_LIMIT = max(MAX_SUBMISSION_BYTES, MAX_NOTEBOOK_BYTES)
"""Bytes of a submission the parent reads (one more shows it is over; the file's verdict says by how much)."""


def default_workers() -> int:
    """The cores this process may run on."""
    return usable_cpus()


def grade_submission(
    path: Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    only: Sequence[str] | None = None,
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL,
    on_progress: Callable[[ProblemResult], None] | None = None,
    config: Path | None = None,
    plan: GradingPlan | None = None,
    name: str | None = None,
) -> Report:
    """Grade one submission file.

    A file that is empty, not UTF-8, not Python or too large gets a report saying so; a student's crash,
    timeout or wrong answer is a verdict in the report. Neither raises.

    Args:
        path: The student's ``.py`` or ``.ipynb`` file.
        seed: Grading seed: the same bytes and seed give the same statuses, scores and measurements.
        workers: Parallel pytest-xdist workers; the machine's cores when None.
        only: Problem ids to grade; all enabled problems when None.
        policy: ``REQUIRE_FULL`` (instructors, the service) refuses to run without full isolation;
            ``ALLOW_FALLBACK`` (a student's own check) runs with what the machine offers.
        on_progress: Called with each problem's result as soon as its check finishes.
        config: Assignment configuration TOML; the bundled one when None.
        plan: A plan made already (`GradingPlan.load`); ``config`` and ``only`` are then not read.
        name: The file's own name as shown to a person, already neutralised, when its copy on disk is
            called otherwise (a worker grades a class's file under a safe name): see `grade_files`'
            ``names``. ``path.name`` when None.

    Returns:
        The report. ``report.grader_errors`` lists failures of the grader itself (the affected problems
        are marked ``error`` with a message saying it is not the student's fault).

    Raises:
        grader.sandbox.errors.IsolationUnavailable: ``REQUIRE_FULL`` and this machine cannot isolate.
        grader.errors.ConfigError: The configuration is invalid.
        grader.errors.UnknownProblem: ``only`` names an unknown problem.
    """
    listener: GradingListener = Silent()
    if on_progress is not None:
        progress = on_progress
        listener = OnResult(lambda _path, result: progress(result))
    chosen = plan or GradingPlan.load(config, only)
    names = {path: name} if name else None
    return grade_files(
        [path], chosen, seed=seed, workers=workers, policy=policy, listener=listener, names=names
    )[0]


def grade_files(
    paths: Sequence[Path],
    plan: GradingPlan,
    *,
    seed: int,
    workers: int | None,
    policy: IsolationPolicy,
    listener: GradingListener | None = None,
    names: Mapping[Path, str] | None = None,
) -> list[Report]:
    """Grade several files in one acceptance session (work spread over all workers), a report per file.

    Args:
        paths: Submission files; invalid ones are reported without running anything.
        plan: The problems to grade and their configuration.
        seed: Grading seed.
        workers: Parallel workers; the machine's cores when None.
        policy: Isolation policy (see ``grade_submission``).
        listener: Hears each problem's result as its check finishes, and each file's report as soon as
            its last check finishes (at once for a file refused without running), so a batch can keep
            each report the moment it exists.
        names: Each file's own name as shown to a person, already neutralised (a class's zip is read
            into numbered files: ``6.py`` on disk is ``policy_iteration.py`` in the download): its
            messages and its report's ``submission`` say it. Only ever shown, never a path; a file's
            ``path.name`` when it has none.

    Returns:
        One report per path, in the order given.

    Raises:
        grader.sandbox.errors.IsolationUnavailable: ``REQUIRE_FULL`` and this machine cannot isolate
            (checked before anything starts, and raised after the session if a worker found it so).
    """
    started = time.perf_counter()
    files = list(dict.fromkeys(paths))
    with tempfile.TemporaryDirectory(prefix="gymgrade-modules-") as modules_dir:
        prepared: dict[Path, tuple[bytes | None, Submission | FileVerdict]] = {}
        for index, path in enumerate(files):
            read = _read(path)
            shown = (names or {}).get(path) or path.name
            prepared[path] = (
                read if isinstance(read, bytes) else None,
                _prepare(path, read, Path(modules_dir) / str(index), plan, shown),
            )
        graded = sum(1 for _, submission in prepared.values() if isinstance(submission, Submission))
        worker_count = min(workers or default_workers(), max(graded * len(plan.problems), 1))
        collector = Outcomes(
            plan, seed=seed, workers=worker_count, listener=listener or Silent(), started=started
        )
        for path, (data, submission) in prepared.items():
            if isinstance(submission, FileVerdict):
                collector.reject(path, data or b"", submission, (names or {}).get(path) or path.name)
            else:
                collector.expect(submission)
        if not collector.graded or not plan.problems:
            collector.close()
            return collector.reports_of(paths)
        if policy is IsolationPolicy.REQUIRE_FULL:
            require_isolation(policy)
        session = SessionPlan(
            grading=plan,
            submissions=tuple(submission.module.resolve() for submission in collector.graded),
            names=tuple(_sandbox_name(submission) for submission in collector.graded),
            seed=seed,
            policy=policy,
        )
        # The scope outlives the session: its harness trees, scratch dirs and cgroups go when it closes.
        with sandbox_scope() as scope:
            end = run_session(session, workers=worker_count, on_outcome=collector.receive, environment=scope)
        collector.close(f"the grading run stopped (pytest exit code {end.exit_code}): {end.log_tail}")
    return collector.reports_of(paths)


def _prepare(
    path: Path, data: bytes | FileVerdict, module_dir: Path, plan: GradingPlan, shown: str
) -> Submission | FileVerdict:
    """The file the sandbox imports for a submission, in ``module_dir`` (the grader's own folder): a copy of
    the bytes read once, or the module built from a notebook; a verdict when it cannot be graded.

    The student's file is never read again after `_read`: a file swapped or linked in meanwhile, or a
    ``<name>.cells.json`` planted beside it, is not what is graded. ``shown`` is the file's own name in
    what a person reads; its kind (notebook or not) and its copies on disk follow ``path.name``."""
    if isinstance(data, FileVerdict):
        return data
    if not is_notebook(path.name):
        verdict = check_source(data, shown)
        read = _read_as_notebook(data, shown, plan, valid=verdict is None)
        if verdict is not None and read is None:
            return verdict
        module_dir.mkdir()
        module = module_dir / path.name
        # A file that is Python only as its notebook's export shows its edition in the module read from it.
        note = _edition_note(data if read is None or verdict is None else read.source.encode(), shown, plan)
        if read is None:
            module.write_bytes(data)
            return Submission(path, data, module, edition_note=note, name=shown)
        module.write_text(read.source, encoding="utf-8")
        write_cells(module, read.cells)
        return Submission(path, data, module, read, edition_note=note, name=shown)
    built = build_module(data, shown, plan.problems)
    if isinstance(built, FileVerdict):
        return built
    module = module_dir / f"{path.name}.py"
    module_dir.mkdir()
    module.write_text(built.source, encoding="utf-8")
    write_cells(module, built.cells)
    note = _edition_note(built.source.encode("utf-8"), shown, plan)
    return Submission(path, data, module, built, edition_note=note, name=shown)


def _read_as_notebook(data: bytes, shown: str, plan: GradingPlan, *, valid: bool) -> NotebookModule | None:
    """A `.py` read as the notebook it may have been (`grader.submission.notebook.script`): the module
    whose import runs what the notebook's would, or None to grade the file as it is (its top level defines
    only, the notebook's rules leave out nothing of it, or the reader could not read it: a file that
    compiled is graded as it always was, one that did not keeps its verdict). A file that is not ``valid``
    Python is read only if it may be an export (IPython's lines as they are, a half-written marked cell)."""
    if not valid:
        if len(data) > MAX_SUBMISSION_BYTES or b"\0" in data:
            return None
        try:
            if not may_be_export(data.decode("utf-8-sig")):
                return None
        except UnicodeDecodeError:
            return None
    elif defines_only(parsing.parse(data), data.decode("utf-8-sig")):
        return None
    served = [problem for problem in plan.problems if _runs_cells_first(plan, problem)]
    edition = EDITIONS.get(plan.edition)
    template = [function.name for function in edition.functions] if edition is not None else []
    # The template's functions that are no problem's may be called too (a check may call a helper); a
    # problem's function is called only when its problem is graded.
    helpers = [name for name in template if name not in plan.registry.ids]
    built = build_script(data, shown, sorted({*plan.problems, *helpers}), served)
    return built if isinstance(built, NotebookModule) else None


def _runs_cells_first(plan: GradingPlan, problem: str) -> bool:
    """Whether the problem's check runs the file's cells before calling its function (compare()'s
    `run_cells`), so the globals it reads come from them, not from the import."""
    settings = plan.registry.problem(problem).settings(plan.assignment)
    return bool(getattr(settings, "run_cells", False))


def _sandbox_name(submission: Submission) -> str:
    """The name the sandbox's messages give a file (``--name``), or "" to let them name its copy as before:
    given only when the file is shown by another name than the sandbox would call its copy (a class's zip
    is read into numbered copies, a worker writes a file under a safe name, a file's own name holds a space
    or a bracket that the sandbox's copy replaces), as its copy would be called (a notebook's module is
    ``<notebook>.py``); so the sandbox's messages say what the grader's own do, whoever wrote the copy."""
    if not submission.name:
        return ""
    notebook = submission.notebook is not None and not submission.notebook.summary.script
    shown = f"{submission.name}.py" if notebook else submission.name
    return "" if shown == sandbox_file_name(submission.module.name) else shown


def _edition_note(source: bytes, name: str, plan: GradingPlan) -> str | None:
    """What the report tells a file written for another edition's problems than the plan's (read with
    `ast`, never run): it is graded as the assignment's edition and told so."""
    graded = EDITIONS.get(plan.edition)
    return None if graded is None else edition_note(graded, detect_source(source, name))


def _read(path: Path) -> bytes | FileVerdict:
    """The submission's bytes, read once without following links (`grader.submission.untrusted_file`)."""
    try:
        return read_untrusted(path, limit=READ_LIMIT)
    except UnsafeFile as error:
        return FileVerdict("error", str(error))
