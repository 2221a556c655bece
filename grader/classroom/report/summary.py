"""The class summary: score distribution, per-problem pass rates, common diagnoses, late and missing students.

Pure: a function of the class's entries (no I/O), independent of their order, identical for identical
reports. Its JSON (``class_summary``) is what the class page shows and what scripts read; every key is
always present.

Diagnoses have no code in the reports: a check's verdict is its ``feedback`` prose (what was expected,
what was measured, the likely cause). Two students get the same diagnosis when their results of the same
problem have the same status and the same feedback once every number is replaced by ``#`` (see
``diagnosis_text``): the checks write one sentence template per cause and fill it with the student's
measurements (``blackjack(14)``, ``212 hands``, a list ``resets 3, 5, 8, ...``: one ``#``), so the
template is the cause. A sandbox outcome (exception, crash, timeout) reads the same way: its message and
traceback are the same template for the same exception once the file's own name (which differs between
students in flat downloads) is replaced too, and a student's own exception message, being different
text, stays a group of its own. tests/grader/classroom/report/test_real_diagnoses.py holds this against the
checks' own feedback for the simulated mistakes of ``grader.simulated_students.behaviours``.
"""

from __future__ import annotations

import hashlib
import re
import statistics
from collections.abc import Iterable, Sequence
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from grader.classroom.report.entries import ClassEntry, EntryStatus
from grader.lab.editions import edition_label
from grader.lab.labs import lab_label
from grader.render.neutral import (
    MAX_DIAGNOSIS_CHARS,
    MAX_IDENTITY_CHARS,
    MAX_NAME_CHARS,
    MAX_NOTE_CHARS,
    bounded,
    display_text,
    safe_href,
)
from grader.report import Status

SUMMARY_FORMAT = 1
HISTOGRAM_BINS = 10
MAX_DIAGNOSES = 100
"""Diagnosis groups kept in the summary, most common first; how many more there were is recorded."""
DIAGNOSED: frozenset[Status] = frozenset({"failed", "error", "timeout", "missing"})
"""Problem statuses that carry a diagnosis (passed and skipped ones do not)."""
KEY_DIGEST_CHARS = 12
FILE_PLACEHOLDER = "<file>"

# A number as the checks print it (14, 0.4170, -771.09, 1e-06), not a digit inside a word (CartPole-v0).
_NUMBER_LIST = re.compile(r"#(?:, #)+(?:, \.\.\.)?")
"""A list of numbers after substitution ("resets 3, 5, 8, ..."): its length differs between students too."""
_NUMBER = re.compile(r"(?<![A-Za-z_\d])(?<!\d\.)[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


class ScoreBin(BaseModel):
    """Submissions whose score lies in [low, high) (the last bin includes high)."""

    model_config = ConfigDict(extra="forbid")

    low: float
    high: float
    count: int


class ScoreDistribution(BaseModel):
    """Scores of every submission with a report (a submission error scores 0)."""

    model_config = ConfigDict(extra="forbid")

    count: int = Field(description="Submissions with a report.")
    max_score: float = Field(description="Points available (the largest of the reports').")
    mean: float | None
    median: float | None
    min: float | None
    max: float | None
    full_marks: int = Field(description="Submissions that passed every graded problem.")
    bins: list[ScoreBin] = Field(description=f"{HISTOGRAM_BINS} equal bins from 0 to max_score.")


class ProblemPassRate(BaseModel):
    """How one problem went across the graded submissions that ran it."""

    model_config = ConfigDict(extra="forbid")

    id: str
    title: str
    max_score: float
    graded: int = Field(description="Graded submissions that ran the problem (skipped ones excluded).")
    passed: int
    pass_rate: float | None = Field(description="passed / graded; None when nobody ran it.")
    statuses: dict[str, int] = Field(description="How many submissions got each status.")


class Diagnosis(BaseModel):
    """One cause of lost points and the students it concerns."""

    model_config = ConfigDict(extra="forbid")

    key: str = Field(description="problem:status:digest of the text; stable across runs and classes.")
    problem: str
    title: str
    status: str
    text: str = Field(description="The feedback with every number replaced by #.")
    count: int = Field(description="Students concerned.")
    identities: list[str]


class OverrideRow(BaseModel):
    """A cell the instructor decided, beside the machine's verdict."""

    model_config = ConfigDict(extra="forbid")

    problem: str = Field(description="A problem id, or total.")
    points: float = Field(description="The instructor's points.")
    machine: float | None = Field(description="The machine's points (None: nothing graded).")
    reason: str


class StudentRow(BaseModel):
    """One student as the class page lists them."""

    model_config = ConfigDict(extra="forbid")

    identity: str
    name: str | None
    status: EntryStatus
    score: float | None = Field(description="The final score (after overrides and the late penalty).")
    max_score: float | None
    late: bool
    note: str
    report_href: str | None = Field(description="Relative, percent-encoded link; None when refused.")
    machine_score: float | None = Field(default=None, description="The machine's score (None: no report).")
    late_penalty: float | None = Field(
        default=None, description="Points the late policy took (None: no policy)."
    )
    extended_to: str | None = Field(default=None, description="Their own due time, when extended.")
    overrides: list[OverrideRow] = Field(default_factory=list, description="The instructor's decisions.")


class ClassSummary(BaseModel):
    """The whole class at a glance (``class.json``)."""

    model_config = ConfigDict(extra="forbid")

    format: int = SUMMARY_FORMAT
    title: str
    lab: str = Field(
        default="",
        description="The lab its reports were graded in, as a person reads it (several, comma-separated, when kept reports of another lab are mixed in); "  # noqa: E501
        "empty when nothing was graded.",
    )
    edition: str = Field(default="", description="The edition its reports were graded in, as `lab`.")
    students: int
    graded: int
    missing: list[str] = Field(description="On the roster, no submission.")
    late: list[str]
    overridden: list[str] = Field(default_factory=list, description="Students with an instructor's override.")
    extended: list[str] = Field(default_factory=list, description="Students with their own due time.")
    submission_errors: list[StudentRow]
    scores: ScoreDistribution
    problems: list[ProblemPassRate]
    diagnoses: list[Diagnosis] = Field(description=f"Most common first; at most {MAX_DIAGNOSES}.")
    diagnoses_left_off: int = Field(description="Less common diagnosis groups not listed.")
    entries: list[StudentRow] = Field(description="Every student, by identity.")


def diagnosis_text(feedback: str, submission: str = "") -> str:
    """The template of a feedback: one line, controls inert, the file name and numbers replaced, bounded.

    Args:
        feedback: A problem result's feedback.
        submission: The report's file name (tracebacks and messages name it: ``File "/submission/x.py"``);
            it becomes ``{FILE_PLACEHOLDER}``, so students whose files are named differently still group.

    Returns:
        The text two students share when their results have the same cause.
    """
    text = feedback[: MAX_DIAGNOSIS_CHARS * 4]
    if submission:
        # The name as a whole word only: the file "a.py" must not turn "data.py" into "dat<file>".
        own_name = re.compile(rf"(?<![\w.-]){re.escape(submission)}(?![\w-])")
        text = own_name.sub(FILE_PLACEHOLDER, text)
    return display_text(_NUMBER_LIST.sub("#", _NUMBER.sub("#", text)), MAX_DIAGNOSIS_CHARS)


def diagnosis_key(problem: str, status: str, text: str) -> str:
    """A short stable key for a diagnosis: ``problem:status:`` and the start of the text's SHA-256."""
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:KEY_DIGEST_CHARS]
    return f"{problem}:{status}:{digest}"


def summarise(entries: Sequence[ClassEntry], *, title: str = "") -> ClassSummary:
    """The class summary as a model (see ``class_summary`` for its JSON).

    Args:
        entries: One entry per student (or group member), in any order.
        title: What the class or assignment is called (shown as the page's heading).

    Returns:
        The summary; lists of students are ordered by identity.
    """
    ordered = sorted(entries, key=lambda entry: (entry.identity, entry.name or ""))
    graded = [entry for entry in ordered if entry.status == "graded" and entry.report is not None]
    return ClassSummary(
        title=display_text(title, MAX_NAME_CHARS),
        lab=_named(lab_label(entry.report.lab) for entry in graded if entry.report is not None),
        edition=_named(edition_label(entry.report.edition) for entry in graded if entry.report is not None),
        students=len(ordered),
        graded=len(graded),
        missing=[_identity(entry) for entry in ordered if entry.status == "missing"],
        late=[_identity(entry) for entry in ordered if entry.late],
        overridden=[_identity(entry) for entry in ordered if entry.overrides],
        extended=[_identity(entry) for entry in ordered if entry.extended_to],
        submission_errors=[_row(entry) for entry in ordered if entry.status == "submission_error"],
        scores=_distribution(ordered),
        problems=_pass_rates(graded),
        diagnoses=(diagnoses := _diagnoses(graded))[:MAX_DIAGNOSES],
        diagnoses_left_off=max(len(diagnoses) - MAX_DIAGNOSES, 0),
        entries=[_row(entry) for entry in ordered],
    )


def _named(labels: Iterable[str]) -> str:
    """The distinct labels, sorted, comma-separated, one line, bounded (a kept report's text is untrusted)."""
    return display_text(", ".join(sorted(set(labels))), MAX_NAME_CHARS)


def class_summary(entries: Sequence[ClassEntry], *, title: str = "") -> dict[str, Any]:
    """The class summary as JSON-able data with stable keys (what ``class.json`` holds).

    Args:
        entries: One entry per student (or group member), in any order.
        title: What the class or assignment is called.

    Returns:
        ``format``, ``title``, ``lab``, ``edition``, ``students``, ``graded``, ``missing``, ``late``,
        ``submission_errors``, ``scores`` (distribution and histogram bins), ``problems`` (pass rates),
        ``diagnoses`` (most common first, with the identities concerned), ``diagnoses_left_off`` and
        ``entries``.
    """
    return summarise(entries, title=title).model_dump(mode="json")


def _identity(entry: ClassEntry) -> str:
    return bounded(entry.identity, MAX_IDENTITY_CHARS)


def _row(entry: ClassEntry) -> StudentRow:
    report = entry.report
    note = entry.note or (report.submission_error or "" if report is not None else "")
    return StudentRow(
        identity=_identity(entry),
        name=None if entry.name is None else bounded(entry.name, MAX_NAME_CHARS),
        status=entry.status,
        score=_score(entry),
        max_score=None if report is None else report.max_score,
        late=entry.late,
        note=bounded(note, MAX_NOTE_CHARS),
        report_href=safe_href(entry.report_href),
        machine_score=None if report is None else report.score,
        late_penalty=entry.late_penalty,
        extended_to=entry.extended_to,
        overrides=[
            OverrideRow(
                problem=override.problem,
                points=override.points,
                machine=override.machine,
                reason=bounded(override.reason, MAX_NOTE_CHARS),
            )
            for override in entry.overrides
        ],
    )


def _score(entry: ClassEntry) -> float | None:
    """The entry's final score: the instructor's decisions', else its report's."""
    if entry.score is not None:
        return entry.score
    return None if entry.report is None else entry.report.score


def _distribution(entries: Iterable[ClassEntry]) -> ScoreDistribution:
    counted = [entry for entry in entries if entry.report is not None and entry.status != "missing"]
    reports = [entry.report for entry in counted if entry.report is not None]
    scores = [score for entry in counted if (score := _score(entry)) is not None]
    top = max((report.max_score for report in reports), default=0.0)
    return ScoreDistribution(
        count=len(scores),
        max_score=top,
        mean=statistics.fmean(scores) if scores else None,
        median=statistics.median(scores) if scores else None,
        min=min(scores, default=None),
        max=max(scores, default=None),
        full_marks=sum(1 for entry in counted if _full_marks(entry)),
        bins=_bins(scores, top),
    )


def _full_marks(entry: ClassEntry) -> bool:
    report = entry.report
    if report is None or not report.problems:
        return False
    return report.full_marks if entry.score is None else entry.score >= report.max_score


def _bins(scores: Sequence[float], top: float) -> list[ScoreBin]:
    if top <= 0:
        return [ScoreBin(low=0.0, high=0.0, count=len(scores))] if scores else []
    width = top / HISTOGRAM_BINS
    counts = [0] * HISTOGRAM_BINS
    for score in scores:
        counts[min(max(int(score / width), 0), HISTOGRAM_BINS - 1)] += 1
    return [
        ScoreBin(low=round(index * width, 9), high=round((index + 1) * width, 9), count=count)
        for index, count in enumerate(counts)
    ]


def _pass_rates(graded: Sequence[ClassEntry]) -> list[ProblemPassRate]:
    rows: dict[str, ProblemPassRate] = {}
    for entry in graded:
        for result in entry.report.problems if entry.report is not None else []:
            row = rows.setdefault(
                result.id,
                ProblemPassRate(
                    id=result.id,
                    title=bounded(result.title, MAX_NAME_CHARS),
                    max_score=result.max_score,
                    graded=0,
                    passed=0,
                    pass_rate=None,
                    statuses={},
                ),
            )
            row.max_score = max(row.max_score, result.max_score)
            row.statuses[result.status] = row.statuses.get(result.status, 0) + 1
            if result.status != "skipped":
                row.graded += 1
            if result.status == "passed":
                row.passed += 1
    for row in rows.values():
        row.pass_rate = row.passed / row.graded if row.graded else None
        row.statuses = dict(sorted(row.statuses.items()))
    order = _problem_order(graded)
    return sorted(rows.values(), key=lambda row: order[row.id])


def _problem_order(graded: Sequence[ClassEntry]) -> dict[str, tuple[int, str]]:
    """Each problem's rank: its earliest position in any report (reports list them in the plan's order)."""
    order: dict[str, tuple[int, str]] = {}
    for entry in graded:
        for index, result in enumerate(entry.report.problems if entry.report is not None else []):
            order[result.id] = min(order.get(result.id, (index, result.id)), (index, result.id))
    return order


def _diagnoses(graded: Sequence[ClassEntry]) -> list[Diagnosis]:
    groups: dict[str, Diagnosis] = {}
    for entry in graded:
        for result in entry.report.problems if entry.report is not None else []:
            if result.status not in DIAGNOSED:
                continue
            text = diagnosis_text(result.feedback, entry.report.submission if entry.report else "")
            key = diagnosis_key(result.id, result.status, text)
            group = groups.setdefault(
                key,
                Diagnosis(
                    key=key,
                    problem=result.id,
                    title=bounded(result.title, MAX_NAME_CHARS),
                    status=result.status,
                    text=text,
                    count=0,
                    identities=[],
                ),
            )
            identity = _identity(entry)
            if identity not in group.identities:
                group.identities.append(identity)
                group.count += 1
    order = _problem_order(graded)
    return sorted(groups.values(), key=lambda group: (-group.count, order[group.problem], group.key))
