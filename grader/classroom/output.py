"""The class's gradebooks in a batch's output directory, rewritten whole after every finished report."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from grader.classroom.gradebooks import GRADEBOOKS, Assignment, GradeRow, class_rows, grades_csv
from grader.classroom.model import ClassDownload
from grader.classroom.roster import Roster
from grader.grading.batch import GRADES_FILE, write_atomically
from grader.report import Report


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
    """

    download: ClassDownload
    identities: Mapping[Path, str]
    problems: Sequence[str]
    roster: Roster | None = None
    formats: Sequence[str] = ()
    assignment: Assignment = field(default_factory=Assignment)
    rows: list[GradeRow] | None = None

    def __call__(self, out_dir: Path, reports: Mapping[Path, Report]) -> None:
        """Write every gradebook from the reports finished so far."""
        by_identity = {self.identities[path]: report for path, report in reports.items()}
        self.rows = class_rows(self.download, by_identity, self.roster)
        write_atomically(out_dir / GRADES_FILE, grades_csv(self.rows, self.problems))
        for name in self.formats:
            file_name, write = GRADEBOOKS[name]
            write_atomically(out_dir / file_name, write(self.rows, self.problems, self.assignment))
