"""Gradescope's ``results.json`` for one report: a test per problem, the summary and the isolation as output.

Gradescope's specification (https://gradescope-autograders.readthedocs.io/en/latest/specs/) is declared
once, as the pydantic models below, so what gymgrade writes is checked against it when it is built. Every
`output` passes through `grader.render.neutral.display_block` as the models are built, as the text
summary does: a control character (ESC, BEL...) of a student's exception message or printed output is shown
as U+FFFD, never handed to Gradescope's page.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

from grader.render.neutral import display_block
from grader.render.text import edition_name, isolation_lines, lab_name, notebook_lines
from grader.report import SHOWN_AT_ONCE, Report, errors_shown, withheld_ids
from grader.submission.gradescope_upload import UploadSeed

if TYPE_CHECKING:
    from grader.lab.assignment import AssignmentConfig

Visibility = Literal["hidden", "after_due_date", "after_published", "visible"]
ShownText = Annotated[str, AfterValidator(display_block)]
"""Text Gradescope shows: controls (but line breaks and tabs) and bidi overrides inert."""
OUTPUT_KEPT_NOTE = (
    "What your code printed is kept for your instructor, not shown here; "
    "run gymgrade check on your own machine to see it."
)
_RESTRICTIVENESS: dict[str, int] = {"visible": 0, "after_published": 1, "after_due_date": 2, "hidden": 3}


def render_gradescope(report: Report, config: AssignmentConfig | None = None) -> str:
    """`results` of a report as Gradescope reads them, visible to students (``config`` is not needed)."""
    return results(report).to_json()


class GradescopeTest(BaseModel):
    """One entry of ``tests``: a problem of the lab (or an instructor-only note)."""

    model_config = ConfigDict(extra="forbid")

    name: str
    number: str
    score: float
    max_score: float
    status: Literal["passed", "failed"]
    output: ShownText
    visibility: Visibility = "visible"


class GradescopeResults(BaseModel):
    """Gradescope's ``results.json``."""

    model_config = ConfigDict(extra="forbid")

    score: float
    execution_time: int | None = Field(
        default=None,
        description="Seconds, as Gradescope's schema gives it (an integer); left out while a problem is withheld.",  # noqa: E501
    )
    output: ShownText
    output_format: Literal["text", "md", "html", "simple_format", "ansi"] = "text"
    visibility: Visibility = "visible"
    stdout_visibility: Visibility = "hidden"
    extra_data: dict[str, object] | None = Field(
        default=None, description="Stored by Gradescope, never shown to students: the grading seed."
    )
    tests: list[GradescopeTest]

    def to_json(self) -> str:
        """results.json as written (unset optional fields left out)."""
        return self.model_dump_json(indent=2, exclude_none=True) + "\n"


def results(
    report: Report, *, visibility: Visibility = "visible", upload: UploadSeed | None = None
) -> GradescopeResults:
    """Gradescope's results for one report: a test per problem, the summary and the isolation as output.

    Nothing a student sees identifies a start or depends on a withheld problem: what the student's code
    printed goes to an instructor-only test per problem (a file could print its starts), the grading seed
    only to an instructor-only test and ``extra_data``; while a problem is withheld (``hidden`` or
    ``after_due_date`` in the assignment), the total score is withheld with it (the results' top-level
    visibility), the grading time is left out and its grader errors are not in the visible output.

    Args:
        report: The grading report.
        visibility: When students see the results of the visible problems.
        upload: The upload's grading seed and its origin, recorded for the instructor (None: not recorded).

    Returns:
        The results; ``score`` is the report's, so partial credit and zero-point problems add up as in
        the gradebook.
    """
    withheld = withheld_ids([problem.model_dump() for problem in report.problems], SHOWN_AT_ONCE)
    tests: list[GradescopeTest] = []
    for index, problem in enumerate(report.problems, start=1):
        # A problem the assignment hides (or shows after the due date) stays so on Gradescope.
        shown_when = visibility if problem.visibility == "visible" else problem.visibility
        tests.append(
            GradescopeTest(
                name=problem.title,
                number=str(index),
                score=problem.score,
                max_score=problem.max_score,
                # A skipped problem (worth nothing, not run) failed nothing; its output says it was not run.
                status="passed" if problem.status in ("passed", "skipped") else "failed",
                output=f"{problem.status}: {problem.feedback}"
                + (f"\n\n{OUTPUT_KEPT_NOTE}" if problem.output else ""),
                visibility=shown_when,
            )
        )
        if problem.output:
            tests.append(
                _instructor_note(f"{problem.title}: what the code printed", f"{index}.1", problem.output)
            )
    lines = [
        f"gymgrade {report.grader_version}, gymnasium {report.gymnasium_version}.",
        f"Lab: {lab_name(report.lab)}.",
        f"Edition: {edition_name(report.edition)}.",
    ]
    if report.edition_note:
        lines.append(report.edition_note)
    if report.notebook is not None:
        lines += notebook_lines(report.notebook)
    if report.submission_error is not None:
        lines.append(report.submission_error)
    lines += isolation_lines(report.isolation)
    lines += [
        f"Grader error (not your fault): {error}" for error in errors_shown(report.grader_errors, withheld)
    ]
    withheld_visibility = max(
        (problem.visibility for problem in report.problems if problem.id in withheld),
        key=_RESTRICTIVENESS.__getitem__,
        default=None,
    )
    if withheld_visibility is not None:
        # The results' own output is withheld with the total; what it says is the students' all the same.
        notes = [*lines, "The total score is shown when every problem's result is."]
        tests.append(
            GradescopeTest(
                name="About this grading",
                number=str(len(report.problems) + 1),
                score=0.0,
                max_score=0.0,
                status="passed",
                output="\n".join(notes),
                visibility=visibility,
            )
        )
    if upload is not None:
        tests.append(_instructor_note("Grading seed", str(len(report.problems) + 2), upload.describe()))
    return GradescopeResults(
        score=report.score,
        execution_time=None if withheld else round(report.execution_time),
        output="\n".join(lines),
        # The total (and the results' own output) follows the most withheld problem: a total shown while a
        # problem is withheld, minus the visible scores, is the withheld score.
        visibility=visibility if withheld_visibility is None else withheld_visibility,
        extra_data=seed_record(upload) if upload is not None else None,
        tests=tests,
    )


def _instructor_note(name: str, number: str, output: str) -> GradescopeTest:
    return GradescopeTest(
        name=f"{name} (instructor only)",
        number=number,
        score=0.0,
        max_score=0.0,
        status="passed",
        output=output,
        visibility="hidden",
    )


def seed_record(upload: UploadSeed) -> dict[str, object]:
    """The upload's grading seed as ``extra_data`` records it (kept by Gradescope, hidden from students)."""
    return {
        "gymgrade": {"seed": upload.seed, "seed_source": upload.source, "identity": list(upload.identity)}
    }


def failed_run(message: str) -> GradescopeResults:
    """Results for a run that graded nothing (no file to grade, the grader could not start)."""
    return GradescopeResults(score=0.0, execution_time=0, output=message, tests=[])
