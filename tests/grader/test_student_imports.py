"""Honest files that import the course's packages (issue 19, item 4) grade as their answers deserve."""

from __future__ import annotations

from pathlib import Path

import pytest

from grader.grading.grade import grade_submission

HONEST = Path(__file__).resolve().parents[2] / "submissions" / "honest"
CHEAP = ("random_blackjack", "blackjack")
"""The two Blackjack problems: each file imports every package at the top and uses them in both."""


@pytest.mark.slow
@pytest.mark.sandbox
@pytest.mark.parametrize("name", ["imports_tqdm.py", "imports_plots_and_tables.py"])
def test_a_file_using_progress_bars_plots_and_tables_passes_with_bounded_output(name: str) -> None:
    report = grade_submission(HONEST / name, seed=0, only=CHEAP)
    assert [(result.id, result.status) for result in report.problems] == [(i, "passed") for i in CHEAP], [
        result.feedback for result in report.problems
    ]
    for result in report.problems:  # progress bars and clear_output keep their last state only
        assert "more bytes of output were dropped" not in result.output
        assert len(result.output.splitlines()) < 60, result.output[:2000]
