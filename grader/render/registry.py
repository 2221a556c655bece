"""The output formats of one report, by the name `gymgrade check --format` takes.

Each format is a pure function of the report (and the configuration it was graded with, whose bars the
HTML report's plots draw) to the exact text written; the CLI only chooses one and prints it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from grader.render.gradescope import render_gradescope
from grader.render.html import render_html
from grader.render.report_json import render_json
from grader.render.text import render_text

if TYPE_CHECKING:
    from grader.lab.assignment import AssignmentConfig
    from grader.report import Report


class Renderer(Protocol):
    """A report as one output format's text, exactly as written (newline included)."""

    def __call__(self, report: Report, config: AssignmentConfig, /) -> str: ...


@dataclass(frozen=True)
class OutputFormat:
    """One way to show a report."""

    render: Renderer
    description: str
    """What `--format NAME` prints, for the command's help."""
    live_progress: bool = False
    """Whether the grading's progress shares stdout ahead of the output (a person reads it as it comes);
    otherwise progress goes to stderr, so that stdout holds exactly the output."""


FORMATS: dict[str, OutputFormat] = {
    "text": OutputFormat(render_text, "live progress and a summary", live_progress=True),
    "json": OutputFormat(render_json, "exactly the report JSON on stdout"),
    "gradescope": OutputFormat(render_gradescope, "exactly Gradescope's results.json on stdout"),
    "html": OutputFormat(render_html, "the self-contained HTML report (plots, replays) on stdout"),
}
"""Every output format of one report; the first is the default."""


def format_help() -> str:
    """`--format`'s help, derived from `FORMATS`."""
    default, *_ = FORMATS
    return "; ".join(
        f"{name}{' (default)' if name == default else ''}: {output.description}"
        for name, output in FORMATS.items()
    )
