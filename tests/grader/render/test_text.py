"""The text summary's pieces: how the student's code was isolated."""

from __future__ import annotations

from typing import Any

import pytest

from grader.render.text import isolation_lines
from grader.report import IsolationSummary


def _layer(name: str, active: bool, required: bool = True, remedy: str = "") -> dict[str, Any]:
    return {
        "name": name,
        "active": active,
        "required": required,
        "detail": f"{name} detail",
        "remedy": remedy,
    }


@pytest.mark.parametrize(
    ("isolation", "expected"),
    [
        (
            {
                "full": True,
                "layers": [_layer("bubblewrap", True), _layer("landlock", False, required=False)],
                "summary": "",
            },
            ["Sandbox: full isolation (bubblewrap)."],
        ),
        (
            {
                "full": False,
                "layers": [
                    _layer("bubblewrap", False, remedy="apt-get install bubblewrap"),
                    _layer("rlimits", True),
                    _layer("landlock", False, required=False),
                ],
                "summary": "",
            },
            [
                "Sandbox: weaker isolation on this machine (fine for checking your own code; "
                "instructors grade with full isolation). Missing:",
                "  - bubblewrap: bubblewrap detail (to fix: apt-get install bubblewrap)",
            ],
        ),
        ({}, []),
    ],
    ids=["full", "laptop-fallback", "file-never-ran"],
)
def test_check_says_how_the_code_was_isolated(isolation: dict[str, Any], expected: list[str]) -> None:
    assert isolation_lines(IsolationSummary.model_validate(isolation) if isolation else None) == expected
