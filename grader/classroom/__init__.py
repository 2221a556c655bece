"""A class is a roster: class downloads (plain folders, Canvas, Gradescope, GitHub Classroom, Moodle,
nbgrader, Blackboard) read safely into one submission per student, rosters, and gradebooks to upload.

Public API (pure but for reading the download and writing zips into a scratch folder)::

    download = discover(Path("class.zip"), layout=None, rule=GradedFileRule(functions=plan.problems),
                        scratch=Path(tmp))
    for submission in download.submissions:   # one per student or group, sorted by identity
        submission.identity, submission.members, submission.graded_file, submission.why
    download.unattributed, download.refused    # Skipped(where, reason), never guessed

In detail:

- `grader.classroom.discover(path, *, layout=None, sections=None, rule=GradedFileRule(), scratch=None,
  limits=Limits(), due=None) -> ClassDownload` reads a class download (folder, LMS zip, or one file) and
  returns one `Submission` per student or group, sorted by identity; `discover_all(paths, **same)` merges
  several. Both are `read_all(paths, layout=, sections=, scratch=, limits=) -> list[ReadDownload]` (each
  download read once, zips extracted once, all within one `tree.Budget` of `limits`) then
  `submissions_of_all(reads, rule=, due=)` (grouping and the graded-file choice, as often as needed without
  reading again: `gymgrade grade` groups again by another edition's functions this way). Pure but for reading
  the download and writing zip entries into `scratch` (zips are refused without it). `ClassDownload(layout,
  root, submissions, unattributed: list[Skipped], refused: list[Skipped], ignored)`, `Skipped(where, reason)`;
  `Submission(identity, display_name, members: tuple[Member, ...], files: tuple[SubmittedFile, ...],
  graded_file: SubmittedFile | None, why, submitted_at, late, source)`, `Member(identity, name, email)`,
  `SubmittedFile(path, relative, original_name)`. A group's identity is its members' joined by `+`; a student
  whose every file was refused still gets a submission (no graded file, `why` says so). `Submission.refused`
  holds the student's refused files (`why` names 5 and counts the rest); a refused zip entry whose name climbs
  out or is absolute is attributed to the folder or zip holding it (`discovery._holder`), never named for a
  student by its name (`../x` at the top is nobody's). Identities are strings as the source writes them
  (leading zeros kept).
- `tree.py`: the safe walk (`read_tree`): never follows links; refuses symlinks, hard links (`st_nlink > 1`),
  devices/FIFOs/sockets, oversize files; ignores hidden names, `__MACOSX`, `__pycache__`; opens zips
  (also nested, up to `Limits.max_zip_depth`) entry by entry into numbered files under `scratch` (entry
  names never reach the file system), refusing absolute and `../` names, symlink and encrypted entries,
  and entries over the size, ratio (zip bomb), total-bytes and count limits. A zip appears in the tree as
  a folder named like it (`alice.zip/opengym.py`).
  What a person reads names the file as the download does, never by its numbered copy:
  `command.file_names_of(submissions)` maps each graded file to `grader.render.neutral.file_name` of its
  `graded_file.relative` (its last part, neutralised, at most 120 characters), carried as data through
  `grade_many(..., file_names=...)` to the feedback, the report's `submission`, the gradebook note and the
  sandbox's messages (`--name`: import errors, tracebacks, compat events), on this machine or the cluster
  (the request's `name`), and through `ClassSources.names` to the similarity check.
- `layouts/`: one module per layout behind `layouts/protocol.py`'s `Layout` (`name`, `title`,
  `score(tree) -> 0..1`, `group(tree) -> Grouping(groups, unattributed)`), registered in
  `layouts.LAYOUTS` (the `--layout` names: plain, canvas, gradescope, github-classroom, moodle, nbgrader,
  blackboard). Recognition takes the highest score >= 0.5, else plain folders. Gradescope's YAML is read by
  a safe loader that reads Ruby tags as plain data. Plain folders (`PlainLayout(sections=None)`) decide
  section levels from the whole download (`section_levels`: every folder of a level holds no file of its
  own and at least two subfolders with code, no subfolder name under two of them), never from one
  student's folder; below them every folder is a student and all under it is theirs (`--sections N`
  says the levels outright).
- `graded_file.py`: `GradedFileRule(names=LAB_FILE_NAMES, functions=plan.problems)` and `choose(files, rule)
  -> (file | None, why)`: the lab's file name (copy numbers ignored, shallowest), else the only candidate,
  else the one defining most lab functions; never tests, conftest, checkpoints.
- `roster.py`: `read_roster(path) -> Roster`; `find(identity, layout)` matches one column per layout
  (`KEY_COLUMNS`: Canvas `id`, GitHub Classroom `github_username`, ...), exactly but for ASCII case
  (`roster_key`; no Unicode case folding: a Kelvin sign is not a K).
- `gradebooks.py` (pure): `class_rows(download, reports_by_identity, roster) -> list[GradeRow]` (a row per
  member, one per student: of several submissions the latest counts; roster students without one; notes; a
  roster row is claimed once, an exact match first: a second claim is a row with `refused_claim` and a note,
  which every LMS format leaves out), `grades_csv`, `canvas_csv`, `gradescope_csv`, `github_classroom_csv`,
  `GRADEBOOKS` (the `--gradebook` registry); every cell through `grader.render.neutral.safe_cell`.
  `output.ClassGradebook` is the `grader.grading.batch.GradebookWriter` that `gymgrade grade` passes to
  `grade_many(..., names=identities, gradebook=...)`: reports are `<identity_stem(identity)>.json` (the resume
  key: the identity percent-encoded, one over `MAX_STEM_CHARS` (150) cut and ended by `~` and 20 hex digits of
  its SHA-256), gradebooks are rewritten at most every `batch.GRADEBOOK_INTERVAL` s and when the batch ends or
  is interrupted.
- `gymgrade grade --html`: the class report's entries come from the rows the batch last wrote
  (`grader.classroom.report.from_batch.entries_from_rows(ClassGradebook.rows, out_dir, page)`: a roster
  student without a submission is `missing`, a submission with nothing gradable `submission_error`, links to
  `<identity_stem>.json`); the page-clash check runs against the identity report files before grading.
- `api/gradebook.py`'s `gradebook_export(session, policy, format, assignment)` serves the same formats
  (`GET /gradebook.csv?format=canvas&assignment_id=...`), each student's service name as identity.
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
