"""Tests of grader/progress.py: following a growing results file, the progress display."""

from __future__ import annotations

import io
from pathlib import Path

from grader.progress import ProgressBar, ResultsFollower, result_line
from grader.report import ProblemResult, ProblemRun


def _run(problem: str, status: str = "passed") -> ProblemRun:
    result = ProblemResult(
        id=problem,
        title=f"Problem {problem}",
        status=status,
        score=1.0,  # type: ignore[arg-type]
        max_score=1.0,
        feedback="ok",
    )
    return ProblemRun(submission="/tmp/a.py", result=result)


def test_follower_returns_only_complete_new_lines(tmp_path: Path) -> None:
    results = tmp_path / "results.jsonl"
    follower = ResultsFollower(results)
    assert follower.poll() == [], "a file not created yet has no results"
    first, second = _run("car").model_dump_json(), _run("taxi", "failed").model_dump_json()
    results.write_text(first + "\n" + second[:10])
    assert [run.result.id for run in follower.poll()] == ["car"]
    with results.open("a") as stream:
        stream.write(second[10:] + "\n")
    assert [run.result.status for run in follower.poll()] == ["failed"]
    assert follower.poll() == []


def test_result_line_names_status_title_and_points() -> None:
    assert result_line(_run("car", "timeout").result) == "[TIMEOUT] Problem car (1/1)"


def test_progress_bar_writes_plain_lines_when_not_a_terminal() -> None:
    stream = io.StringIO()
    bar = ProgressBar(total=2, stream=stream)
    bar.advance("a.py: car passed")
    bar.advance("b.py: car failed")
    assert stream.getvalue() == "1/2 a.py: car passed\n2/2 b.py: car failed\n"
