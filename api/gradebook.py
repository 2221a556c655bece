"""An assignment's gradebook: one CSV row per enrolment of its course with their latest or best graded
submission of it, in gymgrade's own columns or in the import format of Canvas, Gradescope or GitHub Classroom
(grader.classroom.gradebooks). :func:`final_grades` is the one computation of a final grade (overrides and
late penalty applied) that every format, and the score the LMS receives, read."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any, TypeVar

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.courses import gradebook_policy_of, identity, late_policy_of
from api.models import Assignment, JobStatus, Override, Student, Submission
from api.overrides import as_decided, counted_overrides, maxima_of
from api.settings import GradebookPolicy
from grader.classroom.decisions import Decisions, FinalGrade, final_grade
from grader.classroom.gradebooks import GRADEBOOKS, GradeRow
from grader.classroom.gradebooks import Assignment as GradebookNames
from grader.classroom.late import LatePolicy
from grader.classroom.model import Member
from grader.classroom.model import Submission as ClassSubmission
from grader.classroom.roster import RosterEntry
from grader.render.neutral import safe_cell
from grader.report import ProblemResult, Report

Constructed = TypeVar("Constructed", Report, ProblemResult)
REPORTS_PER_QUERY = 500
"""Submission ids per ``IN (...)`` when reports are read (SQLite binds at most 32,766 parameters)."""

GRADEBOOK_FORMATS = ("gymgrade", *GRADEBOOKS)
"""The ``format`` values of the export: gymgrade's own columns, then every ``gymgrade grade --gradebook``."""


def _chosen(session: Session, assignment: Assignment) -> tuple[list[Student], dict[int, Any]]:
    students = list(
        session.scalars(
            select(Student).where(Student.course_id == assignment.course_id).order_by(Student.name)
        )
    )
    graded = session.execute(
        select(
            Submission.id,
            Submission.student_id,
            Submission.created_at,
            Submission.sha256,
            Submission.score,
            Submission.max_score,
        )
        .where(Submission.assignment_id == assignment.id, Submission.status == JobStatus.DONE.value)
        .order_by(Submission.id)
    ).all()
    return students, with_reports(session, kept_submissions(graded, gradebook_policy_of(assignment)))


def kept_submissions(graded: Iterable[Any], policy: GradebookPolicy) -> dict[int, Any]:
    """The graded submission each student is represented by (the gradebook's and the LMS's score).

    Args:
        graded: Rows with ``student_id`` and ``score``, in the order of their ids (upload order).
        policy: The latest, or the best (the latest among ties).

    Returns:
        The kept row by student id.
    """
    chosen: dict[int, Any] = {}
    for row in graded:
        current = chosen.get(row.student_id)
        if (
            current is None
            or policy is GradebookPolicy.LATEST
            or (row.score or 0.0) >= (current.score or 0.0)
        ):
            chosen[row.student_id] = row
    return chosen


@dataclass(frozen=True)
class KeptSubmission:
    """A kept submission's columns that a gradebook and the LMS's score read, its report with them."""

    id: int
    student_id: int
    created_at: datetime
    sha256: str
    score: float | None
    max_score: float | None
    report: dict[str, Any] | None


def with_reports(session: Session, kept: dict[int, Any]) -> dict[int, KeptSubmission]:
    """The kept rows (``kept_submissions``'s, by enrolment) with their reports, read in one query for the
    kept submissions only (a report is the row's largest column: a student's other uploads never need it).
    """
    ids = [row.id for row in kept.values()]
    reports: dict[int, dict[str, Any] | None] = {}
    for start in range(0, len(ids), REPORTS_PER_QUERY):
        chunk = ids[start : start + REPORTS_PER_QUERY]
        found = session.execute(select(Submission.id, Submission.report).where(Submission.id.in_(chunk)))
        reports.update((submission_id, report) for submission_id, report in found)
    return {
        student_id: KeptSubmission(
            row.id, row.student_id, row.created_at, row.sha256, row.score, row.max_score, reports.get(row.id)
        )
        for student_id, row in kept.items()
    }


def gradebook_export(
    session: Session, assignment: Assignment, gradebook_format: str, names: GradebookNames
) -> str:
    """The gradebook in one of ``GRADEBOOK_FORMATS``: ``gymgrade`` is :func:`gradebook_csv`; the others are
    the LMS import CSVs of ``gymgrade grade --gradebook``, with each student's name as their identity (name
    students by their Canvas user id for a Canvas upload, by their GitHub username for GitHub Classroom).

    Raises:
        ValueError: An unknown format.
        grader.classroom.errors.GradebookError: The format lacks what it needs (Canvas: the assignment id).
    """
    if gradebook_format == "gymgrade":
        return gradebook_csv(session, assignment)
    if gradebook_format not in GRADEBOOKS:
        raise ValueError(
            f"unknown gradebook format {gradebook_format!r}: use one of {', '.join(GRADEBOOK_FORMATS)}"
        )
    students, chosen = _chosen(session, assignment)
    problem_ids = _problem_ids(row.report for row in chosen.values())
    reports = {student_id: _report(picked) for student_id, picked in chosen.items()}
    finals = final_grades(session, assignment, chosen, reports)
    rows = []
    for student in students:
        report = reports.get(student.id)
        final = finals[student.id] if student.id in finals else _final(student.id, None, None, {}, None)
        rows.append(
            GradeRow(
                member=Member(student.name, student.name),
                submission=None,
                report=report,
                roster=RosterEntry(
                    student.name, student.name, "", {"id": student.name, "username": student.name}
                ),
                note="; ".join(final.notes),
                final=final,
            )
        )
    _, write = GRADEBOOKS[gradebook_format]
    return write(rows, problem_ids, names)


def final_grades(
    session: Session,
    assignment: Assignment,
    chosen: dict[int, Any],
    reports: Mapping[int, Report | None] | None = None,
) -> dict[int, FinalGrade]:
    """The final grade of each enrolment's kept submission (``chosen``: enrolment id -> its row, with
    ``id``, ``created_at``, ``score``, ``max_score``, ``report``): the instructor's overrides that count for
    it and the assignment's late penalty by its upload time applied. What every gradebook format shows and
    what the LMS receives. ``reports``: the rows' reports as :func:`_report` makes them, where the caller
    made them already (by enrolment id).
    """
    counted = counted_overrides(session, assignment.id, chosen)
    late = late_policy_of(session, assignment)
    made = reports if reports is not None else {}
    return {
        student_id: _final(
            student_id,
            picked,
            made[student_id] if student_id in made else _report(picked),
            counted.get(student_id, {}),
            late,
        )
        for student_id, picked in chosen.items()
    }


def final_total(final: FinalGrade, picked: Any, *, late: bool) -> float | None:
    """The total a gradebook shows and the LMS receives: the decisions' (overrides, a late policy) when there
    are any, else the machine's score of the kept submission ``picked``."""
    return final.total if final.overridden or late else picked.score


def _final(
    student_id: int,
    picked: Any,
    report: Report | None,
    overrides: dict[str, Override],
    late: LatePolicy | None = None,
) -> FinalGrade:
    """The enrolment's grade after the instructor's overrides and the late policy, by the upload's time
    (the machine's when there are neither)."""
    name = identity(student_id)
    decisions = Decisions(
        overrides=as_decided(name, overrides), late=late, maxima=maxima_of(picked.report if picked else None)
    )
    upload = None
    if picked is not None:
        upload = ClassSubmission(
            identity=name,
            display_name=name,
            members=(),
            files=(),
            graded_file=None,
            why="",
            submitted_at=picked.created_at.replace(tzinfo=UTC),
            source="service",
        )
    return final_grade(name, report, upload, decisions)


def _report(picked: Any) -> Report | None:
    """The stored report's scores as a Report (constructed, not validated: only its scores are read)."""
    if picked is None:
        return None
    problems = [
        _constructed(ProblemResult, id=str(problem.get("id")), score=float(problem.get("score") or 0.0))
        for problem in (picked.report or {}).get("problems", [])
    ]
    return _constructed(
        Report, score=float(picked.score or 0.0), max_score=float(picked.max_score or 0.0), problems=problems
    )


def _constructed(model: type[Constructed], **values: Any) -> Constructed:
    """``model.model_construct(**values)`` with the fields' default factories called here: pydantic 2.13
    inspects a factory's signature at each call of its own, which was 80% of a gradebook's time (a
    gradebook of 100 reports: 0.26 of 0.34 s; bench/service_scale.py)."""
    defaults = {
        name: field.default_factory()  # type: ignore[call-arg]  # the report models' take no argument
        for name, field in model.model_fields.items()
        if field.default_factory is not None and name not in values
    }
    return model.model_construct(**defaults, **values)


def gradebook_csv(session: Session, assignment: Assignment) -> str:
    """Build the assignment's gradebook, a row per enrolment of its course.

    Args:
        session: A database session.
        assignment: The assignment: its gradebook policy says which graded submission represents a student
            (the latest, or the best, latest among ties); its late policy (None: no penalties, no
            ``late_penalty`` column).

    Returns:
        CSV text: ``student, submission_id, submitted_at, sha256``, one column per problem (its score),
        ``score, max_score`` (after the instructor's overrides), ``note`` (each override with the machine's
        verdict and its reason); students without a graded submission have empty cells.
    """
    students, chosen = _chosen(session, assignment)
    problem_ids = _problem_ids(row.report for row in chosen.values())
    finals = final_grades(session, assignment, chosen)
    late = assignment.late_policy is not None
    output = io.StringIO()
    writer = csv.writer(output, lineterminator="\n")
    writer.writerow(
        [
            "student",
            "submission_id",
            "submitted_at",
            "sha256",
            *problem_ids,
            *(["late_penalty"] if late else []),
            "score",
            "max_score",
            "note",
        ]
    )
    for student in students:
        picked = chosen.get(student.id)
        if picked is None:
            blanks = [""] * (len(problem_ids) + (1 if late else 0))
            writer.writerow([safe_cell(student.name), "", "", "", *blanks, "", "", ""])
            continue
        final = finals[student.id]
        scores = {
            problem.get("id"): problem.get("score") for problem in (picked.report or {}).get("problems", [])
        }
        scores.update(final.scores)
        writer.writerow(
            [
                safe_cell(student.name),
                picked.id,
                picked.created_at.isoformat(timespec="seconds"),
                picked.sha256,
                *(_number(scores.get(problem_id)) for problem_id in problem_ids),
                *([_number(final.late_penalty)] if late else []),
                _number(final_total(final, picked, late=late)),
                _number(picked.max_score),
                safe_cell("; ".join(final.notes)),
            ]
        )
    return output.getvalue()


def _problem_ids(reports: Iterable[dict[str, Any] | None]) -> list[str]:
    ids: dict[str, None] = {}
    for report in reports:
        for problem in (report or {}).get("problems", []):
            ids.setdefault(str(problem.get("id")), None)
    return list(ids)


def _number(value: object) -> str:
    return "" if value is None else f"{float(value):g}"  # type: ignore[arg-type]
