"""The layouts of class downloads, one module each, in one registry (the ``--layout`` names)."""

from __future__ import annotations

import argparse

from grader.classroom.layouts.blackboard import BlackboardLayout
from grader.classroom.layouts.canvas import CanvasLayout
from grader.classroom.layouts.github_classroom import GitHubClassroomLayout
from grader.classroom.layouts.gradescope import GradescopeLayout
from grader.classroom.layouts.moodle import MoodleLayout
from grader.classroom.layouts.nbgrader import NbgraderLayout
from grader.classroom.layouts.plain import PlainLayout
from grader.classroom.layouts.protocol import Group, Grouping, Layout

LAYOUTS: dict[str, Layout] = {
    layout.name: layout
    for layout in (
        PlainLayout(),
        CanvasLayout(),
        GradescopeLayout(),
        GitHubClassroomLayout(),
        MoodleLayout(),
        NbgraderLayout(),
        BlackboardLayout(),
    )
}
"""Every layout by its ``--layout`` name."""


def add_layout_option(parser: argparse.ArgumentParser) -> None:
    """Give a command that reads a class download the ``--layout`` option (one of `LAYOUTS`)."""
    parser.add_argument(
        "--layout",
        choices=tuple(LAYOUTS),
        default=None,
        help="the download's layout (default: recognised from its names; see docs/instructors.md)",
    )


__all__ = ["LAYOUTS", "Group", "Grouping", "Layout", "add_layout_option"]
