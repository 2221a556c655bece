"""Batch grading: many submissions, a report JSON per file and grades.csv, kept as each file finishes.

The batch core is executor-agnostic: an executor grades files and hands over each report the moment it
exists; the core writes it (atomically) and rewrites ``grades.csv``. Re-running a batch into the same
output directory reuses every report that still matches its file's bytes, seed and configuration, so an
interrupted batch resumes where it stopped. The local executor runs pytest-xdist on this machine;
others (the distributed one in ``api``) are found through the ``gymgrade.executors`` entry points.

In detail:

- `grader/grading/batch.py` (resumable batches): `grade_many(paths, out_dir, *, seed, workers, only, policy,
  config, on_result, executor=None, on_plan=None, names=None, gradebook=None) -> BatchOutcome(reports, reused,
  graded, reasons)` writes each `<name>.json` (`names` maps a file to its identity; `gradebook` is a
  `GradebookWriter`, see `grader.classroom`) (one rename, never half a file) and rewrites `grades.csv` as
  soon as that file's report exists, and reuses a report already in `out_dir` when `stale_reason(report_text,
  data, seed=, plan=)` is None: same sha256, seed, `config_sha256` (`GradingPlan.config_sha256`, the digest of
  the validated configuration, recorded in `Report.config_sha256`), problems and grader version, and no grader
  errors. Interrupted, it raises `grader.errors.BatchInterrupted(finished, total)` (a `KeyboardInterrupt`).
  Who grades is a `BatchExecutor` (`grade(paths, plan, *, seed, listener)`, each report handed to the
  `GradingListener` as soon as it exists; a report that cannot be written becomes that file's grader error,
  never the batch's): `LocalExecutor(workers, policy)` (chunks of `grade_files`, whose collector hands a
  report over when a file's last check arrives) or one found through the entry-point group
  `gymgrade.executors` (`factory(policy) -> BatchExecutor | None`; None when not configured, then local).
"""

from __future__ import annotations

import csv
import hashlib
import io
import os
import tempfile
import time
import urllib.parse
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from pydantic import ValidationError

import grader
from grader.errors import BatchInterrupted
from grader.grading.grade import READ_LIMIT, grade_files
from grader.grading.outcomes import GradingListener
from grader.grading.plan import GradingPlan
from grader.report import ProblemResult, Report
from grader.sandbox import IsolationPolicy
from grader.submission.notebook import NOTEBOOK_SUFFIX
from grader.submission.untrusted_file import UnsafeFile, read_untrusted

CHUNK_SUBMISSIONS = 24
"""Submissions per pytest run: large enough to keep every worker busy, small enough that a run that dies
takes few results with it (its unfinished problems are reported as grader errors, the batch goes on)."""

GRADES_FILE = "grades.csv"
GRADEBOOK_INTERVAL = 1.0
"""Seconds between two rewrites of a class's gradebooks (a rewrite costs O(class size), so rewriting after
every report costs O(n^2)); the gradebooks are always rewritten when the batch ends or is interrupted."""
SUBMISSION_SUFFIXES = (".py", NOTEBOOK_SUFFIX)

ResultCallback = Callable[[Path, ProblemResult], None]
GradebookWriter = Callable[[Path, Mapping[Path, Report]], None]
"""Writes the batch's gradebook(s) into the output directory from the reports finished so far (by file);
called after every report, so an interrupted batch keeps an up-to-date gradebook."""


class BatchExecutor(Protocol):
    """Grades files and hands over each report as soon as that file is done (in any order)."""

    def grade(
        self,
        paths: Sequence[Path],
        plan: GradingPlan,
        *,
        seed: int,
        listener: GradingListener,
        file_names: Mapping[Path, str] | None = None,
    ) -> None:
        """Grade ``paths`` with ``seed`` under ``plan``; tell ``listener`` each result (progress) and each
        file's report once, as it finishes. ``file_names``: each file's own name as shown (see
        ``grade_files``' ``names``), ``path.name`` for a file without one.

        Raises:
            KeyboardInterrupt: The batch was interrupted; reports already handed over are kept.
        """
        ...


@dataclass(frozen=True)
class LocalExecutor:
    """Grades on this machine: chunks of files per pytest-xdist run, spread over the cores.

    Attributes:
        workers: Parallel pytest-xdist workers; the machine's cores when None.
        policy: Isolation policy (see ``grader.grading.grade.grade_submission``).
    """

    workers: int | None = None
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL

    def grade(
        self,
        paths: Sequence[Path],
        plan: GradingPlan,
        *,
        seed: int,
        listener: GradingListener,
        file_names: Mapping[Path, str] | None = None,
    ) -> None:
        """Grade ``paths`` locally; see :class:`BatchExecutor`."""
        for start in range(0, len(paths), CHUNK_SUBMISSIONS):
            chunk = paths[start : start + CHUNK_SUBMISSIONS]
            grade_files(
                chunk,
                plan,
                seed=seed,
                workers=self.workers,
                policy=self.policy,
                listener=listener,
                names=file_names,
            )


def report_names(paths: Sequence[Path]) -> dict[Path, str]:
    """A distinct report file stem per submission (its name, made unique with a counter when needed)."""
    names: dict[Path, str] = {}
    used: set[str] = set()
    for path in paths:
        stem, counter = path.stem, 1
        while stem in used:
            counter += 1
            stem = f"{path.stem}-{counter}"
        used.add(stem)
        names[path] = stem
    return names


MAX_STEM_CHARS = 150
"""Longest report file stem kept as the identity itself (ASCII: bytes = characters). With ``.json`` and
the temporary name of ``write_atomically`` (``.<name>.json.`` and 8 characters) it stays far below the
255-byte name limit of common file systems."""
HASHED_STEM_DIGITS = 20
"""Hex digits of the identity's SHA-256 that end a longer identity's stem (80 bits: no student can make a
name whose stem is another's)."""


def identity_stem(identity: str) -> str:
    """A report file stem for a student's identity: the identity itself, with every character that is not
    safe in a file name percent-encoded (``ada/../x`` -> ``ada%2F..%2Fx``; a leading dot too).

    A stem longer than ``MAX_STEM_CHARS`` is cut (never inside a ``%XX``) and ends with ``~`` and
    ``HASHED_STEM_DIGITS`` hex digits of the identity's SHA-256: bounded (at most ``MAX_STEM_CHARS + 3``
    characters), the same in every run (resuming finds it), and never another identity's stem (it is longer
    than every stem kept whole).
    """
    stem = urllib.parse.quote(identity, safe=" -_.@+,()")
    stem = "%2E" + stem[1:] if stem.startswith(".") else stem
    if len(stem) <= MAX_STEM_CHARS:
        return stem
    head = stem[: MAX_STEM_CHARS - HASHED_STEM_DIGITS + 2]
    if "%" in head[-2:]:
        head = head[: head.rindex("%")]
    digest = hashlib.sha256(identity.encode("utf-8", "surrogatepass")).hexdigest()[:HASHED_STEM_DIGITS]
    return f"{head}~{digest}"


def stale_reason(report_text: str | None, data: bytes | None, *, seed: int, plan: GradingPlan) -> str | None:
    """Why an existing report cannot stand for a file's grade now, or None when it can be reused.

    Args:
        report_text: The report file's text (None: there is none).
        data: The submission's bytes now (None: unreadable, so it is graded to say so).
        seed: The grading seed of this run.
        plan: This run's problems and configuration.

    Returns:
        A short phrase ("the file changed", "graded with seed 3", ...) or None.
    """
    if report_text is None:
        return "not graded yet"
    try:
        report = Report.model_validate_json(report_text)
    except ValidationError:
        return "its report in the output directory is not a gymgrade report"
    if data is None or report.sha256 != hashlib.sha256(data).hexdigest():
        return "the file changed"
    if report.seed != seed:
        return f"graded with seed {report.seed}"
    if not plan.config_sha256 or report.config_sha256 != plan.config_sha256:
        return "graded with another assignment configuration"
    if tuple(problem.id for problem in report.problems) != plan.problems:
        return "graded for other problems"
    if report.grader_version != grader.__version__:
        return f"graded by gymgrade {report.grader_version}"
    if report.grader_errors:
        return "its last grading failed (grader error)"
    return None


@dataclass
class BatchOutcome:
    """What a batch did: every report in the order of the files, and which files it reused or graded."""

    reports: list[Report]
    reused: list[Path]
    graded: list[Path]
    reasons: dict[Path, str] = field(default_factory=dict)
    """Why each graded file needed grading ("not graded yet", "the file changed", ...)."""


class OutputDirectory:
    """The batch's output directory: one ``<name>.json`` per file and ``grades.csv``, each written whole.

    It is the batch's `GradingListener`: a file's report is written the moment it arrives, and each result
    goes on to ``progress``.

    Args:
        out_dir: The directory (created).
        paths: Every file of the batch, in gradebook order.
        plan: The problems graded (the gradebook's columns).
        names: Each file's identity (its report is ``<identity>.json``); file stems when None.
        gradebook: Writes the gradebook; ``grades.csv`` of :func:`write_grades` when None.
        progress: Called with (file, result) as each check finishes.
    """

    def __init__(
        self,
        out_dir: Path,
        paths: Sequence[Path],
        plan: GradingPlan,
        names: Mapping[Path, str] | None = None,
        gradebook: GradebookWriter | None = None,
        progress: ResultCallback | None = None,
    ) -> None:
        out_dir.mkdir(parents=True, exist_ok=True)
        self.out_dir = out_dir
        self.paths = list(paths)
        self.plan = plan
        self.names = dict(names) if names is not None else report_names(paths)
        self.gradebook = gradebook
        self.progress = progress
        self.reports: dict[Path, Report] = {}
        self.pending = False
        self.written_at = -GRADEBOOK_INTERVAL

    def report_path(self, path: Path) -> Path:
        """Where the report of ``path`` is kept."""
        return self.out_dir / f"{identity_stem(self.names[path])}.json"

    def existing_text(self, path: Path) -> str | None:
        """The text of the report file of ``path``, None when there is none or it cannot be read."""
        try:
            return self.report_path(path).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return None

    def reuse(self, path: Path, report: Report) -> None:
        """Count an earlier run's report of ``path`` as this run's (``grades.csv`` is written later)."""
        self.reports[path] = report

    def result(self, path: Path, result: ProblemResult) -> None:
        """A check of ``path`` finished: pass it on to ``progress``."""
        if self.progress is not None:
            self.progress(path, result)

    def report(self, path: Path, report: Report) -> None:
        """Write a finished file's report and rewrite ``grades.csv`` with every file finished so far (a
        class's gradebooks at most every ``GRADEBOOK_INTERVAL`` seconds, the rest at :meth:`flush`).

        A report that cannot be written (the disk refuses the name, a folder is in its place) is that
        submission's grader error, in its gradebook row; the batch goes on, and the next run grades it again.
        """
        try:
            write_atomically(self.report_path(path), report.to_json() + "\n")
        except OSError as error:
            unwritten = unwritten_report(self.report_path(path), error)
            report = report.model_copy(update={"grader_errors": [*report.grader_errors, unwritten]})
        self.reports[path] = report
        if self.gradebook is not None and time.monotonic() - self.written_at < GRADEBOOK_INTERVAL:
            self.pending = True
            return
        self.write_gradebook()

    def flush(self) -> None:
        """Rewrite the gradebook if reports arrived since it was last written."""
        if self.pending:
            self.write_gradebook()

    def write_gradebook(self) -> None:
        """Rewrite ``grades.csv``: a row per finished file, in the batch's order."""
        self.pending = False
        if self.gradebook is not None:
            self.gradebook(self.out_dir, dict(self.reports))
            self.written_at = time.monotonic()
            return
        finished = [path for path in self.paths if path in self.reports]
        names = [self.names[path] for path in finished]
        write_grades(self.out_dir / GRADES_FILE, names, [self.reports[path] for path in finished], self.plan)


def grade_many(
    paths: Sequence[Path],
    out_dir: Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    only: Sequence[str] | None = None,
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL,
    config: Path | None = None,
    on_result: ResultCallback | None = None,
    executor: BatchExecutor | None = None,
    on_plan: Callable[[BatchOutcome], None] | None = None,
    names: Mapping[Path, str] | None = None,
    gradebook: GradebookWriter | None = None,
    regrade: Collection[Path] | None = None,
    file_names: Mapping[Path, str] | None = None,
) -> BatchOutcome:
    """Grade many submissions; keep ``<name>.json`` per submission and ``grades.csv`` in ``out_dir``.

    Each report is written, and ``grades.csv`` rewritten, the moment its file is done, so an interrupted
    batch keeps everything it finished. A file whose report in ``out_dir`` matches its bytes (sha256),
    the seed, the configuration, the problems and the grader version is not graded again. A submission
    that cannot be read, crashes or times out gets its verdicts; nothing it does stops the batch.

    Args:
        paths: Submission files.
        out_dir: Directory for the reports and ``grades.csv`` (created).
        seed: Grading seed.
        workers: Parallel workers of the local executor; the machine's cores when None.
        only: Problem ids to grade; all enabled problems when None.
        policy: Isolation policy of the local executor (see ``grader.grading.grade.grade_submission``).
        config: Assignment configuration TOML; the bundled one when None.
        on_result: Called with (file, result) as each check finishes.
        executor: Who grades; the local executor (``workers``, ``policy``) when None.
        on_plan: Called once before grading with the outcome so far (reused files, files to grade).
        names: Each file's student identity: it names the report (``<identity>.json``, the resume key) and
            the gradebook row; file stems (numbered when they repeat) when None.
        gradebook: Writes the gradebook(s) after each report; ``grades.csv`` by file when None.
        regrade: Grade exactly these files, whatever their reports say; every other file's report in
            ``out_dir`` is taken as it is (never graded, never rewritten; left out when there is none).
            None: grade what is stale.
        file_names: Each file's own name as a person reads it, neutralised (a class's zip is read into
            numbered files); its messages and its report's ``submission`` say it. ``path.name`` when None.

    Returns:
        Every report in the order of ``paths`` (with ``regrade``, those that exist), and which files were
        reused or graded.

    Raises:
        grader.errors.BatchInterrupted: Interrupted; the reports finished so far are in ``out_dir``.
    """
    plan = GradingPlan.load(config, only)
    output = OutputDirectory(out_dir, paths, plan, names, gradebook, on_result)
    outcome = BatchOutcome(reports=[], reused=[], graded=[])
    for path in paths:
        report_text = output.existing_text(path)
        if regrade is not None:
            if path in regrade:
                outcome.graded.append(path)
                outcome.reasons[path] = "regraded on request"
            elif (kept := _parsed(report_text)) is not None:
                output.reuse(path, kept)
                outcome.reused.append(path)
            continue
        reason = stale_reason(report_text, _read(path), seed=seed, plan=plan)
        if reason is None and report_text is not None:
            output.reuse(path, Report.model_validate_json(report_text))
            outcome.reused.append(path)
        else:
            outcome.graded.append(path)
            outcome.reasons[path] = reason or "not graded yet"
    if on_plan is not None:
        on_plan(outcome)
    if outcome.reused or not outcome.graded:
        output.write_gradebook()
    if outcome.graded:
        try:
            (executor or LocalExecutor(workers, policy)).grade(
                outcome.graded, plan, seed=seed, listener=output, file_names=file_names
            )
        except KeyboardInterrupt as interruption:
            raise BatchInterrupted(len(output.reports), len(paths)) from interruption
        finally:
            output.flush()
    outcome.reports = [output.reports[path] for path in paths if path in output.reports]
    return outcome


def _parsed(report_text: str | None) -> Report | None:
    if report_text is None:
        return None
    try:
        return Report.model_validate_json(report_text)
    except ValidationError:
        return None


def recorded_seed(out_dir: Path) -> int | None:
    """The grading seed of the batch whose ``grades.csv`` is in ``out_dir``, or None (no such file, no
    seed column, or several seeds)."""
    try:
        with (out_dir / GRADES_FILE).open(newline="", encoding="utf-8") as stream:
            seeds = {row.get("seed") or "" for row in csv.DictReader(stream)} - {""}
    except (OSError, UnicodeDecodeError, csv.Error):
        return None
    if len(seeds) != 1:
        return None
    value = seeds.pop()
    return int(value) if value.isdigit() else None


def write_grades(path: Path, names: Sequence[str], reports: Sequence[Report], plan: GradingPlan) -> None:
    """Write the gradebook (in one rename): a row per submission (with its grading seed), a column per
    problem's score, the total and a note."""
    stream = io.StringIO()
    writer = csv.writer(stream)
    writer.writerow(["submission", "sha256", "seed", *plan.problems, "total", "max_score", "note"])
    for name, report in zip(names, reports, strict=True):
        scores = {result.id: result.score for result in report.problems}
        note = report.submission_error or "; ".join(report.grader_errors)
        writer.writerow(
            [
                name,
                report.sha256,
                report.seed,
                *(f"{scores.get(problem, 0.0):g}" for problem in plan.problems),
                f"{report.score:g}",
                f"{report.max_score:g}",
                note,
            ]
        )
    write_atomically(path, stream.getvalue())


def unwritten_report(path: Path, error: OSError) -> str:
    """The grader error of a report that could not be written to ``path``."""
    return (
        f"its report could not be written to {path.name} ({error.strerror or error}); "
        "its scores are in the gradebook, and the next run grades it again"
    )


def write_atomically(path: Path, text: str) -> None:
    """Replace ``path`` with ``text`` in one rename, so an interruption never leaves half a file."""
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(handle, "w", encoding="utf-8", newline="") as stream:
            stream.write(text)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def _read(path: Path) -> bytes | None:
    """The bytes grading reads of ``path`` (so their SHA-256 is the report's), None when it refuses them."""
    try:
        return read_untrusted(path, limit=READ_LIMIT)
    except UnsafeFile:
        return None
