"""Tests of grader/render/progress.py: the progress display."""

from __future__ import annotations

import io

from grader.render.progress import ProgressBar, result_line
from grader.report import ProblemResult


def _result(problem: str, status: str = "passed") -> ProblemResult:
    return ProblemResult(
        id=problem,
        title=f"Problem {problem}",
        status=status,  # type: ignore[arg-type]
        score=1.0,
        max_score=1.0,
        feedback="ok",
    )


def test_result_line_names_status_title_and_points() -> None:
    assert result_line(_result("car", "timeout")) == "[TIMEOUT] Problem car (1/1)"


def test_progress_bar_writes_plain_lines_when_not_a_terminal() -> None:
    stream = io.StringIO()
    bar = ProgressBar(total=2, stream=stream)
    bar.advance("a.py: car passed")
    bar.advance("b.py: car failed")
    assert stream.getvalue() == "1/2 a.py: car passed\n2/2 b.py: car failed\n"


def test_progress_bar_shows_a_name_a_student_chose_as_one_inert_line() -> None:
    # Hostile: a file name that clears the terminal and starts a fake line of its own.
    stream = io.StringIO()
    ProgressBar(total=1, stream=stream).advance("\x1b[2J\rmallory.py\n1/1 alice.py: car passed")
    assert stream.getvalue() == "1/1 \ufffd[2J mallory.py 1/1 alice.py: car passed\n"
