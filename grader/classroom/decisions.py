"""The instructor's last word on a student's grade: overrides and the late policy applied to the machine's
verdicts, as one pure function every gradebook and the class report read.

The machine's scores are never changed: a row carries them beside the final ones. A problem override takes
the place of that problem's score; the late penalty is its own number, taken from the sum (never from a
problem); a ``total`` override is the final total itself, the penalty not taken from it again.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime

from grader.classroom.late import Lateness, LatePolicy, lateness
from grader.classroom.model import Submission
from grader.classroom.overrides import NO_OVERRIDES, TOTAL, Override, Overrides, note_of
from grader.report import Report


@dataclass(frozen=True)
class Decisions:
    """What the instructor decided for the class.

    Attributes:
        overrides: Cells set by hand, with reasons.
        late: The late policy (None: no penalties).
        submitted_at: Submission times the instructor gave, by the gradebook's student id (they take the
            place of the download's).
        maxima: The points each graded problem is out of (their sum is the assignment's maximum).
    """

    overrides: Overrides = NO_OVERRIDES
    late: LatePolicy | None = None
    submitted_at: Mapping[str, datetime] = field(default_factory=dict)
    maxima: Mapping[str, float] = field(default_factory=dict)


NO_DECISIONS = Decisions()


@dataclass(frozen=True)
class FinalGrade:
    """One student's grade after the instructor's decisions.

    Attributes:
        scores: Each problem's points after overrides (the machine's where none).
        machine: Each problem's points as the machine graded them (empty without a report).
        overridden: The overrides applied, by problem id (``total`` too).
        lateness: What the late policy made of the submission (None without a policy or a submission).
        total: The final total (None: nothing graded and nothing decided).
        max_score: What the total is out of (None when unknown).
        machine_total: The machine's total (None without a report).
        late: Whether the submission counts as late (None: nobody says).
        notes: What the gradebook's note says of these decisions.
    """

    scores: dict[str, float]
    machine: dict[str, float]
    overridden: dict[str, Override]
    lateness: Lateness | None
    total: float | None
    max_score: float | None
    machine_total: float | None
    late: bool | None
    notes: tuple[str, ...] = ()

    @property
    def late_penalty(self) -> float:
        """The points the late policy takes (0 when none)."""
        return self.lateness.penalty if self.lateness else 0.0


def final_grade(
    student: str, report: Report | None, submission: Submission | None, decisions: Decisions = NO_DECISIONS
) -> FinalGrade:
    """The final grade of ``student`` (as the gradebook names them) from the machine's report.

    Args:
        student: The gradebook's student id (overrides and extensions are keyed on it).
        report: The report of their graded file (None: not graded).
        submission: Their submission (None: they submitted nothing).
        decisions: The instructor's decisions for the class.
    """
    machine = {result.id: result.score for result in report.problems} if report else {}
    mine = dict(decisions.overrides.of(student))
    scores = dict(machine)
    notes: list[str] = []
    for problem, override in mine.items():
        if problem == TOTAL:
            continue
        notes.append(note_of(override, machine.get(problem) if report else None))
        scores[problem] = override.points
    maximum = report.max_score if report else (sum(decisions.maxima.values()) or None)
    found = None
    late = submission.late if submission else None
    if decisions.late is not None and submission is not None:
        given = decisions.submitted_at.get(student, decisions.submitted_at.get(submission.identity))
        found = lateness(
            decisions.late,
            student,
            submitted_at=given or submission.submitted_at,
            marked_late=submission.late,
            max_score=maximum or 0.0,
        )
        if found.submitted_at is not None:
            late = found.days > 0  # within the grace is on time
        if found.note:
            notes.append(found.note)
    penalty = found.penalty if found else 0.0
    total: float | None = None
    if report is not None or mine:
        total = round(max(sum(scores.values()) - penalty, 0.0), 9)
    if TOTAL in mine:
        override = mine[TOTAL]
        machine_said = round(sum(machine.values()) - penalty, 9) if report else None
        notes.append(
            note_of(override, machine_said)
            + (" (the late penalty is not taken from it again)" if penalty else "")
        )
        total = override.points
    return FinalGrade(
        scores=scores,
        machine=machine,
        overridden=mine,
        lateness=found,
        total=total,
        max_score=maximum,
        machine_total=report.score if report else None,
        late=late,
        notes=tuple(notes),
    )
