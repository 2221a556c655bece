"""A class is a roster: class downloads (plain folders, Canvas, Gradescope, GitHub Classroom, Moodle,
nbgrader, Blackboard) read safely into one submission per student, rosters, and gradebooks to upload.

Public API (pure but for reading the download and writing zips into a scratch folder)::

    download = discover(Path("class.zip"), layout=None, rule=GradedFileRule(functions=plan.problems),
                        scratch=Path(tmp))
    for submission in download.submissions:   # one per student or group, sorted by identity
        submission.identity, submission.members, submission.graded_file, submission.why
    download.unattributed, download.refused    # Skipped(where, reason), never guessed
"""

from grader.classroom.discovery import (
    ReadDownload,
    discover,
    discover_all,
    layout_named,
    read_all,
    recognise,
    submissions_of_all,
)
from grader.classroom.graded_file import LAB_FILE_NAMES, GradedFileRule
from grader.classroom.layouts import LAYOUTS
from grader.classroom.model import ClassDownload, Member, Skipped, Submission, SubmittedFile
from grader.classroom.tree import Limits

__all__ = [
    "LAB_FILE_NAMES",
    "LAYOUTS",
    "ClassDownload",
    "GradedFileRule",
    "Limits",
    "Member",
    "ReadDownload",
    "Skipped",
    "Submission",
    "SubmittedFile",
    "discover",
    "discover_all",
    "layout_named",
    "read_all",
    "recognise",
    "submissions_of_all",
]
