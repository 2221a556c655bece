"""The gradebook: one CSV row per student with their latest or best graded submission."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.models import JobStatus, Student, Submission
from api.settings import GradebookPolicy

_FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def gradebook_csv(session: Session, policy: GradebookPolicy) -> str:
    """Build the gradebook of every student.

    Args:
        session: A database session.
        policy: Which graded submission represents a student: the latest, or the best (latest among ties).

    Returns:
        CSV text: ``student, submission_id, submitted_at, sha256``, one column per problem (its score),
        ``score, max_score``; students without a graded submission have empty cells.
    """
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
    problem_ids = _problem_ids(row.report for row in chosen.values())
    output = io.StringIO()
    writer = csv.writer(output, lineterminator="\n")
    writer.writerow(
        ["student", "submission_id", "submitted_at", "sha256", *problem_ids, "score", "max_score"]
    )
    for student in students:
        picked = chosen.get(student.id)
        if picked is None:
            writer.writerow([_cell(student.name), "", "", "", *([""] * len(problem_ids)), "", ""])
            continue
        scores = {
            problem.get("id"): problem.get("score") for problem in (picked.report or {}).get("problems", [])
        }
        writer.writerow(
            [
                _cell(student.name),
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


def _cell(text: str) -> str:
    """Quote a text cell so that spreadsheets never evaluate it as a formula."""
    return "'" + text if text.startswith(_FORMULA_STARTS) else text
