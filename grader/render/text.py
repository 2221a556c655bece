"""The text summary `gymgrade check` prints: every verdict's feedback, the total, the isolation.

Its pieces (`notebook_lines`, `isolation_lines`) are also what the Gradescope output and the HTML report
say of the notebook and the sandbox. The summary is shown through `grader.render.neutral.display_block`
(the Gradescope output too): control characters a student's code raised or printed (ESC, BEL...) are shown
as U+FFFD, never sent to the terminal.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from grader.render.neutral import display_block
from grader.report import IsolationSummary, Report
from grader.submission.notebook import NotebookSummary

if TYPE_CHECKING:
    from grader.lab.assignment import AssignmentConfig


def render_text(report: Report, config: AssignmentConfig | None = None) -> str:
    """`summary` as printed: one line each, ending with a newline (``config`` is not needed)."""
    return summary(report) + "\n"


def summary(report: Report) -> str:
    """The readable end of `gymgrade check`: every verdict's feedback, the total, the isolation."""
    lines = [""]
    if report.notebook is not None:
        lines += notebook_lines(report.notebook)
    if report.submission_error is not None:
        lines.append(report.submission_error)
    else:
        for result in report.problems:
            lines += [f"{result.title}: {result.status}", f"  {result.feedback}"]
    lines.append(
        f"Score: {report.score:g} / {report.max_score:g}" + ("  (full marks)" if report.full_marks else "")
    )
    lines += instructor_lines(report)
    lines.append(f"Lab: {lab_name(report.lab)}")
    lines.append(f"Edition: {edition_name(report.edition)}")
    if report.edition_note:
        lines.append(report.edition_note)
    lines.append(
        f"Practice seed {report.seed}: your instructor grades on different, unseen starts (a held-out seed), so code that only does well from these starts will fail there."  # noqa: E501
    )
    lines += isolation_lines(report.isolation)
    lines += [f"Grader error (not your fault): {error}" for error in report.grader_errors]
    return display_block("\n".join(lines))


def instructor_lines(report: Report) -> list[str]:
    """What the instructor decided of this grade: each override beside the grader's verdict, with its
    reason, the late penalty, and the final score (one block per student of a group's report)."""
    lines: list[str] = []
    for decided in report.instructor:
        whose = f" for {decided.student}" if len(report.instructor) > 1 else ""
        for override in decided.overrides:
            machine = "nothing graded" if override.machine is None else f"{override.machine:g}"
            lines.append(
                f"Your instructor set {override.problem}{whose} to {override.points:g} (the grader gave {machine}): {override.reason}"  # noqa: E501
            )
        if decided.late_note:
            lines.append(f"Late{whose}: {decided.late_note}")
        if decided.final_score is not None:
            lines.append(f"Final score{whose}: {decided.final_score:g} / {report.max_score:g}")
    return lines


def edition_name(name: str) -> str:
    """How a report names its edition to a person: `rl1 (Reinforcement Learning 1: Gymnasium)`."""
    from grader.lab.editions import edition_label  # the packs import the checks: only when a report is shown

    return edition_label(name)


def lab_name(name: str) -> str:
    """How a report names its lab to a person: `opengym (OpenGym AI / Reinforcement Learning 1)`."""
    from grader.lab.labs import lab_label  # the packs import the checks: only when a report is shown

    return lab_label(name)


def notebook_lines(notebook: NotebookSummary) -> list[str]:
    """What of a notebook ran at import, and every statement that did not, cell by cell."""
    if notebook.script:
        lines = [
            f"Your file, read as the notebook it came from: {notebook.kept_statements} imports, definitions and constants ran at import; "  # noqa: E501
            f"{len(notebook.skipped)} statements did not:"
        ]
        lines += [f"  line {entry.line}: {entry.code}  <- {entry.reason}" for entry in notebook.skipped]
        lines += [f"  note: {note}" for note in notebook.ignored]
        return [*lines, ""]
    lines = [
        f"Notebook: {notebook.kept_statements} imports, definitions and constants from {notebook.code_cells} code cells ran at import; "  # noqa: E501
        f"{len(notebook.skipped)} statements did not:"
    ]
    for entry in notebook.skipped:
        label = f"In [{entry.execution_count}]" if entry.execution_count is not None else "no run"
        lines.append(f"  cell {entry.cell} ({label}), line {entry.line}: {entry.code}  <- {entry.reason}")
    lines += [f"  ignored: {note}" for note in notebook.ignored]
    return [*lines, ""]


def isolation_lines(isolation: IsolationSummary | None) -> list[str]:
    """How the student's code was isolated: one line when fully, else each missing layer and its remedy."""
    if isolation is None:
        return []
    if isolation.full:
        names = ", ".join(layer.name for layer in isolation.layers if layer.active)
        return [f"Sandbox: full isolation ({names})."]
    lines = [
        "Sandbox: weaker isolation on this machine (fine for checking your own code; instructors grade with full isolation). "  # noqa: E501
        "Missing:"
    ]
    lines += [
        f"  - {layer.name}: {layer.detail}" + (f" (to fix: {layer.remedy})" if layer.remedy else "")
        for layer in isolation.layers
        if layer.required and not layer.active
    ]
    return lines
