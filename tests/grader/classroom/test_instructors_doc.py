"""Every command docs/instructors.md shows is one `gymgrade` accepts; its layout names are the registry's."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from grader.classroom import LAYOUTS
from grader.cli import build_parser

DOC = Path(__file__).resolve().parents[3] / "docs" / "instructors.md"
COMMANDS = [
    line.split("  #")[0].strip()
    for line in DOC.read_text(encoding="utf-8").splitlines()
    if line.startswith("gymgrade ")
]


@pytest.mark.parametrize("command", COMMANDS, ids=[shlex.split(c)[2] for c in COMMANDS])
def test_each_documented_command_parses(command: str) -> None:
    args = build_parser().parse_args(shlex.split(command)[1:])
    assert args.command == "grade" and args.out == Path("gradebook")


def test_the_documented_layout_names_are_the_registry() -> None:
    named = re.search(
        r"`--layout NAME` says it outright \(([^)]*)\)", DOC.read_text(encoding="utf-8").replace("\n", " ")
    )
    assert named is not None
    assert re.findall(r"`([a-z-]+)`", named[1]) == list(LAYOUTS)
