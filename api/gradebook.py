"""The gradebook: one CSV row per student with their latest or best graded submission, in gymgrade's own
columns or in the import format of Canvas, Gradescope or GitHub Classroom (grader.classroom.gradebooks)."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.models import JobStatus, Student, Submission
from api.settings import GradebookPolicy
from grader.classroom.gradebooks import GRADEBOOKS, Assignment, GradeRow
from grader.classroom.model import Member
from grader.classroom.roster import RosterEntry
from grader.render.neutral import safe_cell
from grader.report import ProblemResult, Report

GRADEBOOK_FORMATS = ("gymgrade", *GRADEBOOKS)
"""The ``format`` values of the export: gymgrade's own columns, then every ``gymgrade grade --gradebook``."""


def _chosen(session: Session, policy: GradebookPolicy) -> tuple[list[Student], dict[int, Any]]:
    students = list(session.scalars(select(Student).order_by(Student.name)))
    graded = session.execute(
        select(
            Submission.id,
            Submission.student_id,
            Submission.created_at,
            Submission.sha256,
            Submission.score,
            Submission.max_score,
            Submission.report,
        )
        .where(Submission.status == JobStatus.DONE.value)
        .order_by(Submission.id)
    ).all()
    chosen: dict[int, Any] = {}
    for row in graded:
        current = chosen.get(row.student_id)
        if (
            current is None
            or policy is GradebookPolicy.LATEST
            or (row.score or 0.0) >= (current.score or 0.0)
        ):
            chosen[row.student_id] = row
    return students, chosen


def gradebook_export(
    session: Session, policy: GradebookPolicy, gradebook_format: str, assignment: Assignment
) -> str:
    """The gradebook in one of ``GRADEBOOK_FORMATS``: ``gymgrade`` is :func:`gradebook_csv`; the others are
    the LMS import CSVs of ``gymgrade grade --gradebook``, with each student's name as their identity (name
    students by their Canvas user id for a Canvas upload, by their GitHub username for GitHub Classroom).

    Raises:
        ValueError: An unknown format.
        grader.classroom.errors.GradebookError: The format lacks what it needs (Canvas: the assignment id).
    """
    if gradebook_format == "gymgrade":
        return gradebook_csv(session, policy)
    if gradebook_format not in GRADEBOOKS:
        raise ValueError(
            f"unknown gradebook format {gradebook_format!r}: use one of {', '.join(GRADEBOOK_FORMATS)}"
        )
    students, chosen = _chosen(session, policy)
    problem_ids = _problem_ids(row.report for row in chosen.values())
    rows = [
        GradeRow(
            member=Member(student.name, student.name),
            submission=None,
            report=_report(chosen.get(student.id)),
            roster=RosterEntry(
                student.name, student.name, "", {"id": student.name, "username": student.name}
            ),
            note="",
        )
        for student in students
    ]
    _, write = GRADEBOOKS[gradebook_format]
    return write(rows, problem_ids, assignment)


def _report(picked: Any) -> Report | None:
    """The stored report's scores as a Report (constructed, not validated: only its scores are read)."""
    if picked is None:
        return None
    problems = [
        ProblemResult.model_construct(id=str(problem.get("id")), score=float(problem.get("score") or 0.0))
        for problem in (picked.report or {}).get("problems", [])
    ]
    return Report.model_construct(
        score=float(picked.score or 0.0), max_score=float(picked.max_score or 0.0), problems=problems
    )


def gradebook_csv(session: Session, policy: GradebookPolicy) -> str:
    """Build the gradebook of every student.

    Args:
        session: A database session.
        policy: Which graded submission represents a student: the latest, or the best (latest among ties).

    Returns:
        CSV text: ``student, submission_id, submitted_at, sha256``, one column per problem (its score),
        ``score, max_score``; students without a graded submission have empty cells.
    """
    students, chosen = _chosen(session, policy)
    problem_ids = _problem_ids(row.report for row in chosen.values())
    output = io.StringIO()
    writer = csv.writer(output, lineterminator="\n")
    writer.writerow(
        ["student", "submission_id", "submitted_at", "sha256", *problem_ids, "score", "max_score"]
    )
    for student in students:
        picked = chosen.get(student.id)
        if picked is None:
            writer.writerow([safe_cell(student.name), "", "", "", *([""] * len(problem_ids)), "", ""])
            continue
        scores = {
            problem.get("id"): problem.get("score") for problem in (picked.report or {}).get("problems", [])
        }
        writer.writerow(
            [
                safe_cell(student.name),
                picked.id,
                picked.created_at.isoformat(timespec="seconds"),
                picked.sha256,
                *(_number(scores.get(problem_id)) for problem_id in problem_ids),
                _number(picked.score),
                _number(picked.max_score),
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
