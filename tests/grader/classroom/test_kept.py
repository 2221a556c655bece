"""Decisions kept in the output directory: a given overrides file is checked, then kept, and read again by a
run without the option; a refused file keeps nothing; --only-students names only students of the class;
a regrade of one student must match the seed, configuration and problems the rest were graded on."""

from __future__ import annotations

from pathlib import Path

import pytest

from grader.classroom import GradedFileRule, discover
from grader.classroom.errors import OverridesError
from grader.classroom.kept import (
    KEPT_OVERRIDES,
    KEPT_TIMES,
    UnknownStudents,
    chosen_submissions,
    load_instructor_data,
    recorded_grading_differs,
)
from grader.report import ProblemResult, Report

from .downloads import BUILDERS

MAXIMA = {"random_blackjack": 1.0, "car": 1.0}
RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))


def _load(out: Path, **given: Path | None):  # type: ignore[no-untyped-def]
    options = {"overrides": None, "submitted_at": None, **given}
    return load_instructor_data(
        out_dir=out,
        config=None,
        students=["alice", "bob"],
        maxima=MAXIMA,
        **options,  # type: ignore[arg-type]
    )


def test_given_overrides_are_kept_and_read_again_without_the_option(tmp_path: Path) -> None:
    given = tmp_path / "mine.csv"
    given.write_text("\ufeffstudent,problem,points,reason\nalice,car,1,checked by hand\n", encoding="utf-8")
    times = tmp_path / "times.csv"
    times.write_text(
        "student,submitted_at\nbob,2026-03-02T01:00:00Z\nzed,2026-03-02T01:00:00Z\n", encoding="utf-8"
    )
    out = tmp_path / "out"
    first = _load(out, overrides=given, submitted_at=times)
    assert not (out / KEPT_OVERRIDES).exists(), "nothing is kept before grading starts"
    first.write_kept(out)
    assert first.lines == [
        f"Overrides: 1 from {given} (kept as {out / KEPT_OVERRIDES} for later runs)",
        f"Submission times: 1 students' from {times}; 1 rows name nobody in the class and are not used",
    ]
    given.unlink()
    again = _load(out)
    assert again.decisions.overrides.of("alice")["car"].reason == "checked by hand"
    assert set(again.decisions.submitted_at) == {"bob", "zed"}
    assert again.lines[0] == (
        f"Overrides: 1 from {out / KEPT_OVERRIDES} (kept from an earlier run; --overrides FILE replaces them)"
    )
    assert (out / KEPT_TIMES).is_file()


def test_a_refused_file_keeps_nothing_and_a_kept_one_is_checked_again(tmp_path: Path) -> None:
    out = tmp_path / "out"
    bad = tmp_path / "bad.csv"
    bad.write_text("student,problem,points,reason\nmallory,car,1,x\n", encoding="utf-8")
    with pytest.raises(OverridesError):
        _load(out, overrides=bad)
    assert not (out / KEPT_OVERRIDES).exists()
    out.mkdir()
    (out / KEPT_OVERRIDES).write_text("student,problem,points,reason\nmallory,car,1,x\n", encoding="utf-8")
    with pytest.raises(OverridesError, match="'mallory' is nobody in this class"):
        _load(out)


def test_only_students_names_students_of_the_class(tmp_path: Path) -> None:
    expected = BUILDERS["gradescope"](tmp_path / "d", 2)
    download = discover(expected.path, rule=RULE, scratch=tmp_path / "s")
    assert chosen_submissions(download, ["003100", "000102"]) == {"003100", "000101+000102"}
    with pytest.raises(UnknownStudents) as raised:
        chosen_submissions(download, ["003100", "=cmd", "3100"])
    assert str(raised.value) == (
        "--only-students names '=cmd', '3100', who submitted nothing in this download: "
        "name students as grades.csv's student column does (comma-separated)"
    )


def _report(seed: int, digest: str, problems: tuple[str, ...]) -> Report:
    return Report(
        submission="x.py", sha256="ab" * 32, seed=seed, gymnasium_version="1.4.0", grader_version="0.1.0",
        score=0.0, max_score=1.0, config_sha256=digest,
        problems=[ProblemResult(id=p, title=p, status="failed", score=0.0, max_score=1.0, feedback="")
                  for p in problems],
    )  # fmt: skip


@pytest.mark.parametrize(
    ("report", "reason"),
    [
        (_report(7, "c1", ("car",)), None),
        (_report(8, "c1", ("car",)), "bob was graded with seed 8, this run grades with 7: pass --seed 8 or leave out --seed"),  # noqa: E501
        (_report(7, "c2", ("car",)), "bob was graded with another assignment configuration: pass the same --config, --lab and --edition as the class's grading"),  # noqa: E501
        (_report(7, "c1", ("car", "taxi")), "bob was graded for car, taxi: pass the same --only as the class's grading"),  # noqa: E501
    ],
    ids=["same", "other-seed", "other-configuration", "other-problems"],
)  # fmt: skip
def test_a_regrade_of_one_matches_the_recorded_grading(report: Report, reason: str | None) -> None:
    assert recorded_grading_differs({"bob": report}, seed=7, config_sha256="c1", problems=("car",)) == reason


def test_a_missing_file_says_so(tmp_path: Path) -> None:
    with pytest.raises(OverridesError, match=r"cannot read the overrides file .*nope\.csv \(No such file"):
        _load(tmp_path / "out", overrides=tmp_path / "nope.csv")
