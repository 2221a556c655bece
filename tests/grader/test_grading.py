"""Tests of grader/grading.py and grader/batch.py: bad files, a batch that survives a crash, grades.csv."""

from __future__ import annotations

import csv
import json
import time
from pathlib import Path

import pytest
from grading_support import CLASSIC_COMPLETE, FAST_OVERRIDES, SUBMISSIONS, write_config

from grader.batch import grade_many
from grader.grading import GradingPlan, grade_files, grade_submission
from grader.report import Report
from grader.sandbox import IsolationPolicy

BAD_FILES = [
    ("empty.py", b"", "missing", "empty.py is empty: nothing to grade."),
    ("image.py", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "error", "image.py is not a text file"),
    (
        "latin1.py",
        b"def car():\n    return 'caf\xe9'\n",
        "error",
        "latin1.py is not UTF-8 text: byte 0xe9 on line 2",
    ),
    (
        "syntax.py",
        b"def car(:\n    return 1\n",
        "error",
        "syntax.py is not valid Python: invalid syntax (line 1",
    ),
]


@pytest.fixture(scope="module")
def fast_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "assignment.toml", FAST_OVERRIDES)


@pytest.mark.parametrize(
    ("name", "data", "status", "message"), BAD_FILES, ids=[case[0].removesuffix(".py") for case in BAD_FILES]
)
def test_bad_files_get_a_clear_verdict_for_every_problem(
    tmp_path: Path, name: str, data: bytes, status: str, message: str
) -> None:
    path = tmp_path / name
    path.write_bytes(data)
    seen: list[str] = []
    report = grade_submission(path, on_progress=lambda result: seen.append(result.id))
    assert report.submission_error is not None and report.submission_error.startswith(message)
    assert {problem.status for problem in report.problems} == {status}
    assert all(problem.feedback == report.submission_error for problem in report.problems)
    assert report.score == 0 and report.max_score > 0
    assert seen == [problem.id for problem in report.problems]
    assert Report.model_validate_json(report.to_json()) == report


def test_unknown_problem_ids_are_refused() -> None:
    with pytest.raises(ValueError, match="unknown problem blackjak; expected ids among random_blackjack"):
        grade_submission(CLASSIC_COMPLETE, only=["blackjak"])


@pytest.fixture(scope="module")
def batch(tmp_path_factory: pytest.TempPathFactory, fast_config: Path) -> tuple[Path, list[Report]]:
    """A batch of the lab solution, a file that kills its own process at import, and an empty file."""
    inputs = tmp_path_factory.mktemp("inputs")
    empty = inputs / "empty.py"
    empty.write_bytes(b"")
    out = tmp_path_factory.mktemp("out")
    paths = [SUBMISSIONS / "hostile" / "os_exit_at_import.py", CLASSIC_COMPLETE, empty]
    reports = grade_many(
        paths,
        out,
        seed=3,
        workers=2,
        only=["car", "random_blackjack"],
        policy=IsolationPolicy.ALLOW_FALLBACK,
        config=fast_config,
    ).reports
    return out, reports


def test_a_crashing_submission_does_not_stop_the_batch(batch: tuple[Path, list[Report]]) -> None:
    _, (crashing, complete, empty) = batch
    assert [problem.status for problem in crashing.problems] == ["error", "error"]
    assert (
        "your file ended the process with exit status 0 while being imported" in crashing.problems[0].feedback
    )
    assert [problem.status for problem in complete.problems] == ["passed", "passed"]
    assert empty.submission_error is not None
    assert all(not report.grader_errors for report in (crashing, complete, empty))


def test_batch_writes_a_report_per_submission_and_grades_csv(batch: tuple[Path, list[Report]]) -> None:
    out, reports = batch
    assert sorted(path.name for path in out.iterdir()) == [
        "classic_complete.json",
        "empty.json",
        "grades.csv",
        "os_exit_at_import.json",
    ]
    written = Report.model_validate(json.loads((out / "classic_complete.json").read_text()))
    assert written == reports[1]
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [row["submission"] for row in rows] == ["os_exit_at_import", "classic_complete", "empty"]
    assert list(rows[0]) == [
        "submission",
        "sha256",
        "seed",
        "random_blackjack",
        "car",
        "total",
        "max_score",
        "note",
    ]
    assert {row["seed"] for row in rows} == {"3"}
    assert [(row["total"], row["max_score"]) for row in rows] == [("0", "2"), ("2", "2"), ("0", "2")]


def _processes(argument: str | None = None, group: int | None = None) -> list[int]:
    """Live processes whose command line holds ``argument`` or whose process group is ``group``."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            command = (entry / "cmdline").read_bytes().split(b"\0")
            state, pgrp = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0:4:3]
        except (OSError, ValueError):
            continue
        if state != "Z" and (
            (argument is not None and argument.encode() in command)
            or (group is not None and int(pgrp) == group)
        ):
            found.append(int(entry.name))
    return found


def test_an_abandoned_run_leaves_no_process_behind(fast_config: Path) -> None:
    seed = 918273645  # marks this run's pytest command line
    plan = GradingPlan.load(fast_config, ["car", "cartpole", "random_blackjack"])
    controllers: list[int] = []

    def give_up(path: Path, result: object) -> None:
        controllers.extend(_processes(argument=str(seed)))
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        grade_files(
            [CLASSIC_COMPLETE],
            plan,
            seed=seed,
            workers=2,
            policy=IsolationPolicy.ALLOW_FALLBACK,
            on_result=give_up,
        )
    [controller] = controllers
    deadline = time.monotonic() + 10  # SIGKILLed workers take a moment to exit
    while _processes(group=controller) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _processes(group=controller) == [], "the pytest run and its xdist workers must be gone"


def test_each_result_carries_its_problems_visibility(tmp_path: Path) -> None:
    overrides = {
        **FAST_OVERRIDES,
        "cartpole": {**FAST_OVERRIDES["cartpole"], "visibility": "after_due_date"},
        "car": {**FAST_OVERRIDES["car"], "visibility": "hidden"},
    }
    config = write_config(tmp_path / "assignment.toml", overrides)
    empty = tmp_path / "empty.py"
    empty.write_bytes(b"")
    plan = GradingPlan.load(config, ["cartpole", "car", "taxi"])
    assert plan.visibility == {"cartpole": "after_due_date", "car": "hidden", "taxi": "visible"}

    graded = grade_submission(
        CLASSIC_COMPLETE,
        seed=3,
        workers=1,
        only=["car"],
        policy=IsolationPolicy.ALLOW_FALLBACK,
        config=config,
    )
    assert [(result.id, result.status, result.visibility) for result in graded.problems] == [
        ("car", "passed", "hidden")
    ]
    rejected = grade_submission(empty, only=["cartpole", "car", "taxi"], config=config)
    assert [(result.id, result.visibility) for result in rejected.problems] == [
        ("cartpole", "after_due_date"),
        ("car", "hidden"),
        ("taxi", "visible"),
    ]
