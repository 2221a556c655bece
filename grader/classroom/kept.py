"""What the instructor decided, kept in the batch's output directory so that every later run respects it.

``--overrides FILE`` and ``--submitted-at FILE`` are read, checked against the class, and only then copied
into ``--out`` (``overrides.csv``, ``submitted_at.csv``); a later run without the option reads the copy
there, so a regrade or a resumed batch never drops an override. Giving the option again replaces the copy.
Also here: which students ``--only-students`` names, and whether an output directory's recorded grading
matches the configuration a regrade of one student would use.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from grader.classroom.decisions import Decisions
from grader.classroom.errors import ClassroomError, LatePolicyError, OverridesError
from grader.classroom.late import read_late_policy
from grader.classroom.model import ClassDownload
from grader.classroom.overrides import MAX_OVERRIDES_BYTES, check_overrides, parse_overrides
from grader.classroom.submitted_at import MAX_TIMES_BYTES, parse_submitted_at
from grader.grading.batch import write_atomically
from grader.render.neutral import IDENTITY_SHOWN_CHARS, display_identity
from grader.report import Report

KEPT_OVERRIDES = "overrides.csv"
KEPT_TIMES = "submitted_at.csv"


class UnknownStudents(ClassroomError):
    """Raised when ``--only-students`` names someone the class does not have."""


@dataclass
class InstructorData:
    """The decisions of a run and what to say of them.

    Attributes:
        decisions: Overrides, late policy, given times, problem maxima.
        lines: What to print (which files were read, kept, reused).
        keep: File name in the output directory -> bytes to write there once grading starts.
    """

    decisions: Decisions
    lines: list[str] = field(default_factory=list)
    keep: dict[str, bytes] = field(default_factory=dict)

    def write_kept(self, out_dir: Path) -> None:
        """Copy the files given this run into ``out_dir`` (after they were accepted)."""
        out_dir.mkdir(parents=True, exist_ok=True)
        for name, data in self.keep.items():
            write_atomically(out_dir / name, data.decode("utf-8-sig"))


def _source(
    given: Path | None, out_dir: Path, kept: str, limit: int, refused: type[ClassroomError], what: str
) -> tuple[bytes, str, bool] | None:
    """The bytes to read (given, else kept in ``out_dir``), where they come from, and whether given."""
    path = given if given is not None else out_dir / kept
    if given is None and not path.is_file():
        return None
    try:
        with path.open("rb") as stream:
            return stream.read(limit + 1), str(path), given is not None
    except OSError as error:
        raise refused(
            f"cannot read the {what} {path} ({error.strerror or error}): pass a readable CSV"
        ) from None


def load_instructor_data(
    *,
    out_dir: Path,
    config: Path | None,
    overrides: Path | None,
    submitted_at: Path | None,
    students: Collection[str],
    maxima: Mapping[str, float],
) -> InstructorData:
    """The instructor's decisions for a class run into ``out_dir``.

    Args:
        out_dir: The batch's output directory (where earlier decisions are kept).
        config: The assignment configuration (its ``[late]`` table); the bundled one when None.
        overrides: ``--overrides FILE``, else the copy kept in ``out_dir``, if any.
        submitted_at: ``--submitted-at FILE``, else the copy kept in ``out_dir``, if any.
        students: Every student of the class as the gradebook names them.
        maxima: The points each graded problem is out of.

    Raises:
        grader.classroom.errors.ClassroomError: A file is refused (its message lists every fault) or the
            late policy is invalid.
    """
    data = InstructorData(Decisions(maxima=dict(maxima), late=read_late_policy(config)))
    found = _source(overrides, out_dir, KEPT_OVERRIDES, MAX_OVERRIDES_BYTES, OverridesError, "overrides file")
    if found is not None:
        raw, where, given = found
        rows = parse_overrides(raw, where=where)
        checked = check_overrides(rows, students=students, maxima=maxima, where=where)
        data.decisions = Decisions(overrides=checked, late=data.decisions.late, maxima=data.decisions.maxima)
        if given:
            data.keep[KEPT_OVERRIDES] = raw
        data.lines.append(
            f"Overrides: {len(checked)} from {where}"
            + (
                f" (kept as {out_dir / KEPT_OVERRIDES} for later runs)"
                if given
                else " (kept from an earlier run; --overrides FILE replaces them)"
            )
        )
    found = _source(submitted_at, out_dir, KEPT_TIMES, MAX_TIMES_BYTES, LatePolicyError, "submission times")
    if found is not None:
        raw, where, given = found
        times = parse_submitted_at(raw, where=where)
        data.decisions = Decisions(
            overrides=data.decisions.overrides, late=data.decisions.late, submitted_at=times,
            maxima=data.decisions.maxima,
        )  # fmt: skip
        if given:
            data.keep[KEPT_TIMES] = raw
        strangers = sorted(set(times) - set(students))
        data.lines.append(
            f"Submission times: {len(times) - len(strangers)} students' from {where}"
            + (f"; {len(strangers)} rows name nobody in the class and are not used" if strangers else "")
        )
    late = data.decisions.late
    if late is not None:
        data.lines.append(
            f"Late policy: due {late.due.isoformat()}, {late.penalty_per_day:g} of the maximum per day or part of a day, at most {late.max_penalty:g}"  # noqa: E501
            + (f", {late.grace_minutes:g} minutes' grace" if late.grace_minutes else "")
            + (f", {len(late.extensions)} extensions" if late.extensions else "")
        )
    return data


def chosen_submissions(download: ClassDownload, names: Sequence[str]) -> set[str]:
    """The submission identities ``--only-students`` names (a member of a group names the group's).

    Raises:
        UnknownStudents: A name is nobody in the download (the message lists them and says what to use).
    """
    chosen: set[str] = set()
    unknown: list[str] = []
    for name in names:
        found = {
            submission.identity
            for submission in download.submissions
            if submission.identity == name or any(member.identity == name for member in submission.members)
        }
        if not found:
            unknown.append(name)
        chosen |= found
    if unknown:
        shown = ", ".join(repr(display_identity(name, IDENTITY_SHOWN_CHARS)) for name in unknown[:10])
        raise UnknownStudents(
            f"--only-students names {shown}, who submitted nothing in this download: "
            "name students as grades.csv's student column does (comma-separated)"
        )
    return chosen


def recorded_grading_differs(
    reports: Mapping[str, Report], *, seed: int, config_sha256: str, problems: Sequence[str]
) -> str | None:
    """Why grading some students on ``seed``, the configuration ``config_sha256`` and ``problems`` would
    not match the reports already in the output directory (by identity), or None when it would."""
    for identity, report in sorted(reports.items()):
        shown = display_identity(identity, IDENTITY_SHOWN_CHARS)
        if report.seed != seed:
            return f"{shown} was graded with seed {report.seed}, this run grades with {seed}: pass --seed {report.seed} or leave out --seed"  # noqa: E501
        if report.config_sha256 != config_sha256:
            return f"{shown} was graded with another assignment configuration: pass the same --config, --lab and --edition as the class's grading"  # noqa: E501
        if tuple(result.id for result in report.problems) != tuple(problems):
            return f"{shown} was graded for {', '.join(r.id for r in report.problems)}: pass the same --only as the class's grading"  # noqa: E501
    return None


def regrade_refusal(
    out_dir: Path, others: Collection[str], *, seed: int, config_sha256: str, problems: Sequence[str]
) -> str | None:
    """Why ``--only-students`` cannot regrade into ``out_dir``: nothing graded there yet, or the other
    students' reports (by identity) were graded on another seed, configuration or problems; None when it can.
    """
    from grader.grading.batch import identity_stem

    reports: dict[str, Report] = {}
    for identity in others:
        try:
            text = (out_dir / f"{identity_stem(identity)}.json").read_text(encoding="utf-8")
            reports[identity] = Report.model_validate_json(text)
        except (OSError, UnicodeDecodeError, ValueError):
            continue
    if not reports and not (out_dir / "grades.csv").is_file():
        return f"--only-students regrades students of a class already graded in {out_dir}, and nothing is graded there: run without --only-students first"  # noqa: E501
    return recorded_grading_differs(reports, seed=seed, config_sha256=config_sha256, problems=problems)
