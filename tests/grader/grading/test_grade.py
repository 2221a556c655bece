"""Tests of grader/grading/grade.py and grader/grading/batch.py: bad files, a batch that survives a crash,
grades.csv."""

from __future__ import annotations

import csv
import json
import os
import time
from pathlib import Path
from typing import NoReturn

import pytest
from grading_support import CLASSIC_COMPLETE, FAST_OVERRIDES, SUBMISSIONS, write_config

import grader.grading.grade
import grader.sandbox.runner
from grader.errors import BatchInterrupted
from grader.grading.batch import grade_many
from grader.grading.grade import grade_files, grade_submission
from grader.grading.outcomes import OnResult
from grader.grading.plan import GradingPlan
from grader.grading.plugin import GraderFailure, SessionPlan
from grader.grading.session import OutcomeCallback, SessionEnd
from grader.report import Report
from grader.sandbox import IsolationPolicy
from grader.sandbox.errors import IsolationUnavailable
from grader.sandbox.isolation.layer import IsolationReport, LayerReport

pytestmark = pytest.mark.slow  # each test grades through pytest-xdist sessions and the sandbox

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


@pytest.mark.parametrize("kind", ["symbolic", "hard"])
def test_a_linked_submission_is_refused_without_reading_its_target(tmp_path: Path, kind: str) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("hunter2\n")
    path = tmp_path / "opengym.py"
    if kind == "symbolic":
        path.symlink_to(secret)
        message = (
            f"opengym.py is a symbolic link (to {secret}): links are never followed, so it was not read."
        )
    else:
        os.link(secret, path)
        message = "opengym.py is a hard link (2 names for one file, possibly outside the submission)"
    report = grade_submission(path)
    assert report.submission_error is not None and report.submission_error.startswith(message)
    assert {problem.status for problem in report.problems} == {"error"} and report.score == 0
    assert "hunter2" not in report.to_json()


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


@pytest.mark.xdist_group("grade-batch")  # one worker grades `batch` for all
def test_a_crashing_submission_does_not_stop_the_batch(batch: tuple[Path, list[Report]]) -> None:
    _, (crashing, complete, empty) = batch
    assert [problem.status for problem in crashing.problems] == ["error", "error"]
    assert (
        "your file ended the process with exit status 0 while being imported" in crashing.problems[0].feedback
    )
    assert [problem.status for problem in complete.problems] == ["passed", "passed"]
    assert empty.submission_error is not None
    assert all(not report.grader_errors for report in (crashing, complete, empty))


@pytest.mark.xdist_group("grade-batch")  # one worker grades `batch` for all
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


def _children() -> set[int]:
    """Live processes whose parent is this one (the session's xdist workers, while it runs)."""
    found = set()
    for entry in Path("/proc").iterdir():
        try:
            state, parent = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0:2]
        except (OSError, ValueError):
            continue
        if state != "Z" and int(parent) == os.getpid():
            found.add(int(entry.name))
    return found


def test_an_abandoned_run_leaves_no_process_behind(fast_config: Path) -> None:
    plan = GradingPlan.load(fast_config, ["car", "cartpole", "random_blackjack"])
    workers: set[int] = set()
    before = _children()  # processes earlier tests of this run left as children (servers, fixtures)

    def give_up(path: Path, result: object) -> None:
        workers.update(_children() - before)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        grade_files(
            [CLASSIC_COMPLETE],
            plan,
            seed=918273645,
            workers=2,
            policy=IsolationPolicy.ALLOW_FALLBACK,
            listener=OnResult(give_up),
        )
    assert workers, "the session's workers are children of the calling process"
    deadline = time.monotonic() + 120  # SIGKILLed workers take a moment to exit; this bounds a hang only
    while workers & _children() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not workers & _children(), "the session's xdist workers must be gone"


def test_a_batch_interrupted_in_a_callback_says_how_much_is_kept(tmp_path: Path, fast_config: Path) -> None:
    def interrupt(path: Path, result: object) -> None:
        raise KeyboardInterrupt

    with pytest.raises(BatchInterrupted) as interrupted:
        grade_many(
            [CLASSIC_COMPLETE],
            tmp_path / "out",
            seed=3,
            workers=1,
            only=["car"],
            policy=IsolationPolicy.ALLOW_FALLBACK,
            config=fast_config,
            on_result=interrupt,
        )
    assert (interrupted.value.finished, interrupted.value.total) == (0, 1)


def test_full_isolation_is_refused_before_anything_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    weak = IsolationReport(
        (LayerReport("bubblewrap", False, "bwrap is missing", "apt-get install bubblewrap"),)
    )
    monkeypatch.setattr(grader.sandbox.runner, "probe_isolation", lambda: weak)
    monkeypatch.setattr(grader.grading.grade, "run_session", _never_called)
    with pytest.raises(IsolationUnavailable, match="- bubblewrap: bwrap is missing; to fix: apt-get install"):
        grade_submission(CLASSIC_COMPLETE, only=["car"], policy=IsolationPolicy.REQUIRE_FULL)


def _never_called(*args: object, **kwargs: object) -> NoReturn:
    raise AssertionError("no session may start")


def test_isolation_a_worker_finds_unavailable_is_raised_after_the_session(
    monkeypatch: pytest.MonkeyPatch, fast_config: Path
) -> None:
    def refuse(plan: SessionPlan, *, on_outcome: OutcomeCallback, **options: object) -> SessionEnd:
        failure = GraderFailure(kind="isolation_unavailable", detail="worker: no seccomp")
        on_outcome(plan.cases()[0], failure)
        return SessionEnd(exit_code=1, log_tail="")

    monkeypatch.setattr(grader.grading.grade, "run_session", refuse)
    seen: list[str] = []
    with pytest.raises(IsolationUnavailable, match=r"^worker: no seccomp$"):
        grade_submission(
            CLASSIC_COMPLETE,
            only=["car"],
            policy=IsolationPolicy.ALLOW_FALLBACK,
            config=fast_config,
            on_progress=lambda result: seen.append(result.id),
        )
    assert seen == [], "a check that could not be isolated is not a result"


def test_cases_a_stopped_session_left_without_outcome_are_grader_errors(
    monkeypatch: pytest.MonkeyPatch, fast_config: Path
) -> None:
    monkeypatch.setattr(
        grader.grading.grade,
        "run_session",
        lambda *args, **kwargs: SessionEnd(exit_code=3, log_tail="INTERNALERROR> boom"),
    )
    report = grade_submission(
        CLASSIC_COMPLETE, only=["car", "taxi"], policy=IsolationPolicy.ALLOW_FALLBACK, config=fast_config
    )
    assert [problem.status for problem in report.problems] == ["error", "error"]
    assert report.grader_errors == [
        f"{problem}: the grading run stopped (pytest exit code 3): INTERNALERROR> boom"
        for problem in ("car", "taxi")
    ]


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


def test_the_workers_a_report_records_are_those_its_valid_files_needed(
    tmp_path: Path, fast_config: Path
) -> None:
    empty = tmp_path / "empty.py"
    empty.write_bytes(b"")
    plan = GradingPlan.load(fast_config, ["car"])
    refused, graded = grade_files(
        [empty, CLASSIC_COMPLETE], plan, seed=3, workers=2, policy=IsolationPolicy.ALLOW_FALLBACK
    )
    assert refused.submission_error is not None and refused.timings is None
    assert graded.timings is not None and graded.timings.workers == 1  # one case: one worker, not two


@pytest.mark.parametrize(
    ("copy", "shown", "sandbox_name"),
    [
        ("opengym.py", "opengym.py", ""),
        ("opengym.py", "", ""),
        ("6.py", "smithjohn_3001_7001_policy_iteration-1.py", "smithjohn_3001_7001_policy_iteration-1.py"),
        (
            "submission.py",
            "smithjohn_3001_7001_policy_iteration-1.py",
            "smithjohn_3001_7001_policy_iteration-1.py",
        ),
        ("opengym (1).py", "opengym (1).py", "opengym (1).py"),
        ("submission.py", "my lab.py", "my lab.py"),
    ],
    ids=["own-name", "no-name", "zip-copy", "worker-copy", "folder-name-with-a-space", "upload-name"],
)
def test_the_sandbox_is_given_the_shown_name_whenever_its_copy_would_be_called_otherwise(
    tmp_path: Path, copy: str, shown: str, sandbox_name: str
) -> None:
    """Whoever wrote the copy (a zip read into numbered files, a worker's safe name) and whatever the sandbox
    makes of its name (a space becomes ``_``), its messages name the file as the grader's own do."""
    from grader.grading.grade import _sandbox_name
    from grader.grading.outcomes import Submission

    submission = Submission(tmp_path / copy, b"", tmp_path / "0" / copy, name=shown)
    assert _sandbox_name(submission) == sandbox_name
