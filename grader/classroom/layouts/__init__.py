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
    """Give a command that reads a class download the ``--layout`` option (one of `LAYOUTS`) and plain
    folders' ``--sections N``."""
    parser.add_argument(
        "--layout",
        choices=tuple(LAYOUTS),
        default=None,
        help="the download's layout (default: recognised from its names; see docs/instructors.md)",
    )
    parser.add_argument(
        "--sections",
        type=_levels,
        default=None,
        metavar="N",
        help="plain folders: N levels of section folders hold the students' folders; "
        "0: the top folders are the students; by default decided from the download's shape as a whole",
    )


def _levels(text: str) -> int:
    try:
        levels = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number of folder levels (0, 1, 2...), found {text!r}"
        ) from None
    if not 0 <= levels <= 32:
        raise argparse.ArgumentTypeError(f"expected 0 to 32 levels of section folders, found {levels}")
    return levels


__all__ = ["LAYOUTS", "Group", "Grouping", "Layout", "add_layout_option"]
