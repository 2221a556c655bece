"""Tests of grader/batch.py that need no grading run: finding files, naming reports, grades.csv."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from grader.batch import collect_submissions, report_names, write_grades
from grader.grading import GradingPlan
from grader.report import ProblemResult, Report


def test_collect_submissions_walks_directories_in_order(tmp_path: Path) -> None:
    for relative in ["b/opengym.py", "a/opengym.py", "a/notes.txt", ".git/hook.py", "c.py"]:
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text("x = 1\n")
    found = collect_submissions([tmp_path / "a", tmp_path / "b", tmp_path / "c.py"])
    assert found == [tmp_path / "a/opengym.py", tmp_path / "b/opengym.py", tmp_path / "c.py"]
    hidden = collect_submissions([tmp_path])
    assert tmp_path / ".git/hook.py" not in hidden


def test_collect_submissions_takes_notebooks_but_not_their_checkpoints(tmp_path: Path) -> None:
    for relative in ["ada/lab.ipynb", "ada/.ipynb_checkpoints/lab-checkpoint.ipynb", "bob/opengym.py"]:
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text("{}")
    assert collect_submissions([tmp_path]) == [tmp_path / "ada/lab.ipynb", tmp_path / "bob/opengym.py"]


def test_collect_submissions_names_a_missing_target(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"nope\.py does not exist"):
        collect_submissions([tmp_path / "nope.py"])


def test_report_names_are_unique() -> None:
    paths = [Path("a/opengym.py"), Path("b/opengym.py"), Path("c/alice.py"), Path("d/opengym.py")]
    assert list(report_names(paths).values()) == ["opengym", "opengym-2", "alice", "opengym-3"]


def _report(name: str, scores: dict[str, float], error: str | None = None) -> Report:
    problems = [
        ProblemResult(
            id=problem,
            title=problem,
            status="passed" if score else "failed",
            score=score,
            max_score=1.0,
            feedback="",
        )
        for problem, score in scores.items()
    ]
    return Report(
        submission=name,
        sha256="0" * 64,
        seed=0,
        gymnasium_version="1.4.0",
        grader_version="0.1.0",
        score=sum(scores.values()),
        max_score=float(len(scores)),
        problems=problems,
        submission_error=error,
    )


def test_grades_csv_has_a_row_per_submission_and_a_column_per_problem(tmp_path: Path) -> None:
    plan = GradingPlan(
        problems=("cartpole", "car"),
        points={"cartpole": 1.0, "car": 1.0},
        titles={"cartpole": "CartPole", "car": "MountainCar"},
        config=None,
    )
    reports = [
        _report("alice.py", {"cartpole": 1.0, "car": 0.0}),
        _report("bob.py", {"cartpole": 0.0, "car": 0.0}, error="bob.py is empty"),
    ]
    write_grades(tmp_path / "grades.csv", ["alice", "bob"], reports, plan)
    rows = list(csv.reader((tmp_path / "grades.csv").open()))
    assert rows == [
        ["submission", "sha256", "cartpole", "car", "total", "max_score", "note"],
        ["alice", "0" * 64, "1", "0", "1", "2", ""],
        ["bob", "0" * 64, "0", "0", "0", "2", "bob.py is empty"],
    ]
