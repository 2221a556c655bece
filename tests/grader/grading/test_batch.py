"""Tests of grader/grading/batch.py that need no grading run: files, report names, grades.csv, resuming."""

from __future__ import annotations

import csv
import hashlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from grading_support import write_config

import grader
from grader.errors import BatchInterrupted
from grader.grading.batch import (
    GRADES_FILE,
    MAX_STEM_CHARS,
    grade_many,
    identity_stem,
    report_names,
    write_grades,
)
from grader.grading.outcomes import GradingListener
from grader.grading.plan import GradingPlan
from grader.report import ProblemResult, Report


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
    plan = GradingPlan.load(None, ["cartpole", "car"])
    reports = [
        _report("alice.py", {"cartpole": 1.0, "car": 0.0}),
        _report("bob.py", {"cartpole": 0.0, "car": 0.0}, error="bob.py is empty"),
    ]
    write_grades(tmp_path / "grades.csv", ["alice", "bob"], reports, plan)
    rows = list(csv.reader((tmp_path / "grades.csv").open()))
    assert rows == [
        ["submission", "sha256", "seed", "cartpole", "car", "total", "max_score", "note"],
        ["alice", "0" * 64, "0", "1", "0", "1", "2", ""],
        ["bob", "0" * 64, "0", "0", "0", "0", "2", "bob.py is empty"],
    ]


# Resumable batches: a fake executor grades instantly and records what it was asked to grade.

ONLY = ("cartpole", "car")


@dataclass
class FakeExecutor:
    """Grades each file into a report of its bytes; can be told to stop (as Ctrl-C would) after N files."""

    interrupt_after: int | None = None
    asked: list[list[str]] = field(default_factory=list)

    def grade(
        self,
        paths: Sequence[Path],
        plan: GradingPlan,
        *,
        seed: int,
        listener: GradingListener,
        file_names: Mapping[Path, str] | None = None,
    ) -> None:
        self.asked.append([path.name for path in paths])
        for done, path in enumerate(paths):
            if self.interrupt_after is not None and done >= self.interrupt_after:
                raise KeyboardInterrupt
            listener.report(path, graded_report(path, plan, seed))


def graded_report(path: Path, plan: GradingPlan, seed: int) -> Report:
    data = path.read_bytes()
    report = _report(path.name, {problem: float(len(data) % 2) for problem in plan.problems})
    return report.model_copy(
        update={
            "sha256": hashlib.sha256(data).hexdigest(),
            "seed": seed,
            "config_sha256": plan.config_sha256,
            "grader_version": grader.__version__,
        }
    )


@pytest.fixture
def inputs(tmp_path: Path) -> list[Path]:
    folder = tmp_path / "inputs"
    folder.mkdir()
    for name, text in [("alice.py", "a = 1\n"), ("bob.py", "b = 22\n"), ("carol.py", "c = 333\n")]:
        (folder / name).write_text(text)
    return sorted(folder.glob("*.py"))


def _rows(out: Path) -> list[str]:
    return [row["submission"] for row in csv.DictReader((out / GRADES_FILE).open())]


def test_a_second_run_reuses_every_matching_report(tmp_path: Path, inputs: list[Path]) -> None:
    executor = FakeExecutor()
    first = grade_many(inputs, tmp_path / "out", seed=4, only=ONLY, executor=executor)
    second = grade_many(inputs, tmp_path / "out", seed=4, only=ONLY, executor=executor)
    assert executor.asked == [["alice.py", "bob.py", "carol.py"]], "the second run graded nothing"
    assert (first.graded, second.reused, second.graded) == (inputs, inputs, [])
    assert second.reports == first.reports
    assert _rows(tmp_path / "out") == ["alice", "bob", "carol"]


@pytest.mark.parametrize(
    ("damage", "reason"),
    [
        (
            lambda out, files: (out / "bob.json").write_text('{"format": 1, "submis'),
            "is not a gymgrade report",
        ),
        (lambda out, files: (out / "bob.json").write_text('{"grades": [1, 2]}'), "is not a gymgrade report"),
        (lambda out, files: (out / "bob.json").unlink(), "not graded yet"),
        (lambda out, files: files[1].write_text("b = 23\n"), "the file changed"),
        (
            lambda out, files: (out / "bob.json").write_text((out / "alice.json").read_text()),
            "the file changed",
        ),
    ],
    ids=["truncated-report", "foreign-json", "deleted-report", "changed-file", "another-files-report"],
)
def test_only_files_whose_report_no_longer_matches_are_graded_again(
    tmp_path: Path, inputs: list[Path], damage: Callable[[Path, list[Path]], object], reason: str
) -> None:
    out = tmp_path / "out"
    grade_many(inputs, out, seed=4, only=ONLY, executor=FakeExecutor())
    damage(out, inputs)
    executor = FakeExecutor()
    outcome = grade_many(inputs, out, seed=4, only=ONLY, executor=executor)
    assert executor.asked == [["bob.py"]]
    assert reason in outcome.reasons[inputs[1]]
    assert Report.model_validate_json((out / "bob.json").read_text()) == outcome.reports[1]
    assert _rows(out) == ["alice", "bob", "carol"]


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ({"seed": 5}, "graded with seed 4"),
        ({"only": ("car",)}, "graded for other problems"),
        ({"config": "points"}, "graded with another assignment configuration"),
    ],
    ids=["seed", "problems", "config"],
)
def test_a_changed_seed_selection_or_configuration_grades_everything_again(
    tmp_path: Path, inputs: list[Path], change: dict[str, object], reason: str
) -> None:
    out = tmp_path / "out"
    grade_many(inputs, out, seed=4, only=ONLY, executor=FakeExecutor())
    options: dict[str, object] = {"seed": 4, "only": ONLY, **change}
    if change.get("config") == "points":
        options["config"] = write_config(tmp_path / "assignment.toml", {"car": {"points": 2.0}})
    executor = FakeExecutor()
    outcome = grade_many(inputs, out, executor=executor, **options)  # type: ignore[arg-type]
    assert executor.asked == [["alice.py", "bob.py", "carol.py"]]
    assert {outcome.reasons[path] for path in inputs} == {reason}


def test_an_interrupted_batch_keeps_what_it_finished_and_resumes(tmp_path: Path, inputs: list[Path]) -> None:
    out = tmp_path / "out"
    with pytest.raises(BatchInterrupted) as interrupted:
        grade_many(inputs, out, seed=4, only=ONLY, executor=FakeExecutor(interrupt_after=1))
    assert (interrupted.value.finished, interrupted.value.total) == (1, 3)
    assert sorted(path.name for path in out.iterdir()) == ["alice.json", GRADES_FILE]
    assert _rows(out) == ["alice"]
    executor = FakeExecutor()
    outcome = grade_many(inputs, out, seed=4, only=ONLY, executor=executor)
    assert executor.asked == [["bob.py", "carol.py"]]
    assert outcome.reused == inputs[:1]
    assert _rows(out) == ["alice", "bob", "carol"]


def test_a_report_listing_grader_errors_is_graded_again(tmp_path: Path, inputs: list[Path]) -> None:
    out = tmp_path / "out"
    grade_many(inputs, out, seed=4, only=ONLY, executor=FakeExecutor())
    broken = Report.model_validate_json((out / "carol.json").read_text())
    (out / "carol.json").write_text(broken.model_copy(update={"grader_errors": ["car: died"]}).to_json())
    executor = FakeExecutor()
    outcome = grade_many(inputs, out, seed=4, only=ONLY, executor=executor)
    assert executor.asked == [["carol.py"]]
    assert outcome.reasons[inputs[2]] == "its last grading failed (grader error)"


# Report names a student chose: bounded, stable, distinct; a report that cannot be written is that student's.

LONG_NAMES = ["1" + "é" * 80, "1" + "é" * 79 + "e", "x" * 150, "x" * 151, "y" * 100_000, "%" * 60]


@pytest.mark.parametrize(
    "identity", LONG_NAMES, ids=["161-bytes", "its-neighbour", "150", "151", "100k", "percent"]
)
def test_a_long_identity_gets_a_bounded_stable_report_name(identity: str) -> None:
    stem = identity_stem(identity)
    assert len(stem) <= MAX_STEM_CHARS + 3
    assert stem.isascii() and "/" not in stem
    assert identity_stem(identity) == stem, "the same name in every run, so a re-run resumes"


def test_long_identities_never_share_a_report_name() -> None:
    stems = [identity_stem(identity) for identity in LONG_NAMES]
    assert len(set(stems)) == len(stems)
    assert identity_stem("x" * 150) == "x" * 150, "a stem that fits is kept whole, as before"
    kept_whole = identity_stem("x" * 150)
    hashed = identity_stem("x" * 151)
    assert len(hashed) > MAX_STEM_CHARS >= len(kept_whole), "no name kept whole can equal a hashed one"


def test_a_161_byte_folder_name_is_graded_and_resumed(tmp_path: Path, inputs: list[Path]) -> None:
    names = {inputs[0]: "1" + "é" * 80, inputs[1]: "bob", inputs[2]: "carol"}
    out = tmp_path / "out"
    first = grade_many(inputs, out, seed=4, only=ONLY, executor=FakeExecutor(), names=names)
    assert [report.grader_errors for report in first.reports] == [[], [], []]
    executor = FakeExecutor()
    second = grade_many(inputs, out, seed=4, only=ONLY, executor=executor, names=names)
    assert (executor.asked, second.reused) == ([], inputs)


def test_a_report_that_cannot_be_written_is_that_students_grader_error(
    tmp_path: Path, inputs: list[Path]
) -> None:
    out = tmp_path / "out"
    (out / "bob.json").mkdir(parents=True)  # a folder where bob's report goes: the rename fails
    outcome = grade_many(inputs, out, seed=4, only=ONLY, executor=FakeExecutor())
    assert [report.grader_errors for report in outcome.reports] == [
        [],
        [
            "its report could not be written to bob.json (Is a directory); "
            "its scores are in the gradebook, and the next run grades it again"
        ],
        [],
    ]
    assert _rows(out) == ["alice", "bob", "carol"]
    assert sorted(path.name for path in out.glob("*.json")) == ["alice.json", "bob.json", "carol.json"]
    assert (out / "carol.json").is_file() and (out / "bob.json").is_dir()
