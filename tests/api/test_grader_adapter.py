"""The adapter that calls the configured grader (GYMGRADE_GRADER): what it passes to graders old and new."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from api.grader_adapter import ImportedGrader, accepts
from grader.report import Report


def _report(submission: str) -> Report:
    return Report(
        submission=submission,
        sha256="0" * 64,
        seed=1,
        config_sha256="",
        gymnasium_version="1.4.0",
        grader_version="test",
        score=0.0,
        max_score=0.0,
    )


def grader_of_before_the_name(
    path: Path, *, seed: int, workers: int | None, policy: Any, on_progress: Any
) -> Report:
    """A grader written before ``name`` existed: it names the file by its path."""
    return _report(path.name)


def grader_with_the_name(
    path: Path, *, seed: int, workers: int | None, policy: Any, on_progress: Any, name: str | None = None
) -> Report:
    return _report(name or path.name)


def grader_with_keywords(path: Path, **options: Any) -> Report:
    return _report(str(options.get("name") or path.name))


@pytest.mark.parametrize(
    ("function", "name", "submission"),
    [
        ("grader_of_before_the_name", "my lab.py", "submission.py"),
        ("grader_with_the_name", "my lab.py", "my lab.py"),
        ("grader_with_the_name", None, "submission.py"),
        ("grader_with_keywords", "my lab.py", "my lab.py"),
    ],
    ids=["grader-without-name", "grader-with-name", "no-name-given", "grader-with-keywords"],
)
def test_the_shown_name_goes_to_graders_that_take_it_and_no_other(
    tmp_path: Path, function: str, name: str | None, submission: str
) -> None:
    grader = ImportedGrader(target=f"{__name__}:{function}")
    report = grader(tmp_path / "submission.py", seed=1, on_progress=lambda _: None, name=name)
    assert report["submission"] == submission


def test_accepts_tells_a_keyword_from_a_missing_one() -> None:
    assert accepts(grader_with_the_name, "name") and accepts(grader_with_keywords, "name")
    assert not accepts(grader_of_before_the_name, "name")
    assert not accepts(len, "name")
