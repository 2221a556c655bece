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


@pytest.mark.parametrize(
    "note", [None, "This file looks written for edition 1 (classic, ...): it imports gym."]
)
def test_the_edition_note_is_shown_under_the_edition_in_text_and_gradescope(note: str | None) -> None:
    from grader.render.gradescope import results
    from grader.render.text import summary
    from grader.report import Report

    report = Report(
        submission="opengym.py",
        sha256="ab" * 32,
        seed=7,
        edition="rl1",
        edition_note=note,
        gymnasium_version="1.4.0",
        grader_version="0.1.0",
        score=0.0,
        max_score=0.0,
    )
    lines = summary(report).splitlines()
    edition = lines.index("Edition: rl1 (Reinforcement Learning 1: Gymnasium)")
    output = results(report).output
    if note is None:
        assert "looks written for" not in summary(report) and "looks written for" not in output
    else:
        assert lines[edition + 1] == note
        assert f"Edition: rl1 (Reinforcement Learning 1: Gymnasium).\n{note}" in output
