"""The class's gradebooks in a batch's output directory, rewritten whole after every finished report."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from grader.classroom.decisions import NO_DECISIONS, Decisions
from grader.classroom.gradebooks import GRADEBOOKS, Assignment, GradeRow, class_rows, grades_csv
from grader.classroom.model import ClassDownload
from grader.classroom.overrides import TOTAL
from grader.classroom.roster import Roster
from grader.grading.batch import GRADES_FILE, identity_stem, write_atomically
from grader.report import InstructorDecisions, InstructorOverride, Report


@dataclass
class ClassGradebook:
    """A ``grader.grading.batch.GradebookWriter`` writing ``grades.csv`` and each ``--gradebook`` format by
    identity.

    Attributes:
        download: The class's submissions.
        identities: The submission identity of each graded file.
        problems: The gradebook's problem columns.
        roster: The roster, if any.
        formats: ``GRADEBOOKS`` names to write beside ``grades.csv``.
        assignment: Title, LMS id and points of the assignment.
        decisions: The instructor's overrides and late policy, applied to every gradebook.
    """

    download: ClassDownload
    identities: Mapping[Path, str]
    problems: Sequence[str]
    roster: Roster | None = None
    formats: Sequence[str] = ()
    assignment: Assignment = field(default_factory=Assignment)
    rows: list[GradeRow] | None = None
    decisions: Decisions = NO_DECISIONS
    decided: dict[str, list[InstructorDecisions]] = field(default_factory=dict)
    """What each report file (by submission identity) last had written of the instructor's decisions."""

    def __call__(self, out_dir: Path, reports: Mapping[Path, Report]) -> None:
        """Write every gradebook from the reports finished so far."""
        by_identity = {self.identities[path]: report for path, report in reports.items()}
        self.rows = class_rows(self.download, by_identity, self.roster, self.decisions)
        grades = grades_csv(self.rows, self.problems, late_penalty=self.decisions.late is not None)
        write_atomically(out_dir / GRADES_FILE, grades)
        for name in self.formats:
            file_name, write = GRADEBOOKS[name]
            write_atomically(out_dir / file_name, write(self.rows, self.problems, self.assignment))
        self._write_decisions(out_dir, by_identity)

    def _write_decisions(self, out_dir: Path, reports: Mapping[str, Report]) -> None:
        """Put each student's overrides and late penalty into their report file (``instructor``), rewriting
        a report only when what it holds of them changed; the machine's verdicts are left as they are."""
        wanted: dict[str, list[InstructorDecisions]] = {}
        for row in self.rows or []:
            if row.submission is None or row.submission.identity not in reports:
                continue
            grade = row.grade
            late = (
                grade.lateness if grade.lateness and (grade.lateness.penalty or grade.lateness.note) else None
            )
            if not grade.overridden and late is None:
                continue
            wanted.setdefault(row.submission.identity, []).append(
                InstructorDecisions(
                    student=row.member.identity,
                    overrides=[
                        InstructorOverride(
                            problem=problem,
                            points=override.points,
                            machine=grade.machine_total if problem == TOTAL else grade.machine.get(problem),
                            reason=override.reason,
                        )
                        for problem, override in grade.overridden.items()
                    ],
                    late_penalty=late.penalty if late else None,
                    late_note=late.note if late else "",
                    final_score=grade.total,
                )
            )
        for identity, report in reports.items():
            decisions = wanted.get(identity, [])
            if self.decided.get(identity, report.instructor) == decisions:
                continue
            try:
                text = report.model_copy(update={"instructor": decisions}).to_json() + "\n"
                write_atomically(out_dir / f"{identity_stem(identity)}.json", text)
            except OSError:
                continue  # the report's own write failed the same way: its row says so
            self.decided[identity] = decisions
