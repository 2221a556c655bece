"""The instructor's decisions in every gradebook: an override changes its cell with the machine's verdict and
the reason in the note, the late penalty is its own column taken from the total (never from a problem), a
total override is the last word, and with no decisions every gradebook is the machine's."""

from __future__ import annotations

import csv
import io
from datetime import timedelta
from pathlib import Path

import pytest

from grader.classroom import GradedFileRule, discover
from grader.classroom.decisions import Decisions, final_grade
from grader.classroom.gradebooks import (
    Assignment,
    canvas_csv,
    class_rows,
    github_classroom_csv,
    grades_csv,
    gradescope_csv,
)
from grader.classroom.late import LatePolicy
from grader.classroom.overrides import check_overrides, parse_overrides
from grader.report import ProblemResult, Report

from .downloads import BUILDERS, DUE, LATE

PROBLEMS = ("random_blackjack", "car")
MAXIMA = {"random_blackjack": 1.0, "car": 1.0}
RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))
POLICY = LatePolicy(due=DUE, penalty_per_day=0.25, max_penalty=0.5, grace_minutes=10)


def _report(car: float) -> Report:
    results = [
        ProblemResult(id="random_blackjack", title="A", status="passed", score=1.0, max_score=1.0, feedback=""),  # noqa: E501
        ProblemResult(id="car", title="B", status="failed" if car < 1 else "passed", score=car, max_score=1.0,
                      feedback=""),
    ]  # fmt: skip
    return Report(
        submission="opengym.py", sha256="ab" * 32, seed=42, gymnasium_version="1.4.0", grader_version="0.1.0",
        score=1.0 + car, max_score=2.0, problems=results,
    )  # fmt: skip


def _decisions(text: str, students: list[str], **options: object) -> Decisions:
    rows = parse_overrides(text.encode(), where="o.csv")
    overrides = check_overrides(rows, students=students, maxima=MAXIMA, where="o.csv")
    return Decisions(overrides=overrides, maxima=MAXIMA, **options)  # type: ignore[arg-type]


def _rows(tmp_path: Path, text: str, **options: object):  # type: ignore[no-untyped-def]
    download = discover(
        BUILDERS["gradescope"](tmp_path / "d", 2).path, rule=RULE, scratch=tmp_path / "s", due=DUE
    )
    reports = {s.identity: _report(0.0) for s in download.submissions if s.graded_file}
    students = [m.identity for s in download.submissions for m in s.members]
    return class_rows(download, reports, None, _decisions(text, students, **options))


def _csv(text: str) -> dict[str, dict[str, str]]:
    return {row.get("student") or row.get("SID") or row["github_username"]: row
            for row in csv.DictReader(io.StringIO(text))}  # fmt: skip


OVERRIDES = (
    "student,problem,points,reason\n"
    '003100,car,1,"=HYPERLINK(""http://evil"",""ok"")"\n'
    "000103,total,2,excused: hospital note\n"
    "000101,car,0.5,partial credit after review\n"
)


def test_every_gradebook_shows_the_overrides_and_the_penalty(tmp_path: Path) -> None:
    rows = _rows(tmp_path, OVERRIDES, late=POLICY)
    grades = _csv(grades_csv(rows, PROBLEMS, late_penalty=True))
    assert {
        who: (row["car"], row["late"], row["late_penalty"], row["total"]) for who, row in grades.items()
    } == {
        "003100": ("1", "on time", "0", "2"),
        "003101": ("0", "on time", "0", "1"),
        "000101": ("0.5", "on time", "0", "1.5"),
        "000102": ("0", "on time", "0", "1"),
        "000103": ("0", "late", "0.5", "2"),
        "000104": ("0", "on time", "0", "1"),
        "000105": ("", "on time", "0", ""),
    }
    assert grades["000103"]["note"] == (
        "1 day late (submitted 2026-03-02T04:59:00+00:00, due 2026-03-01T23:59:00+00:00): 0.5 points taken; "
        "total overridden to 2 (machine: 0.5): excused: hospital note (the late penalty is not taken from it again)"  # noqa: E501
    )
    gradescope = _csv(gradescope_csv(rows, PROBLEMS))
    assert {who: (row["car"], row["Total Score"]) for who, row in gradescope.items()}["000101"] == (
        "0.5",
        "1.5",
    )
    github = _csv(github_classroom_csv(rows))
    assert github["000103"]["points_awarded"] == "2"
    canvas = canvas_csv(rows, Assignment(lms_id="7"))
    assert (
        canvas.count("\r\n") == 2
    )  # no Canvas user ids in a Gradescope export: only Points Possible + header


def test_a_formula_reason_is_inert_in_the_csv(tmp_path: Path) -> None:
    rows = _rows(tmp_path, OVERRIDES)
    text = grades_csv(rows, PROBLEMS)
    note = _csv(text)["003100"]["note"]
    assert note == 'car overridden to 1 (machine: 0): =HYPERLINK("http://evil","ok")'
    assert ",=HYPERLINK" not in text and '"=HYPERLINK' not in text  # the cell starts with its problem id


def test_without_decisions_every_gradebook_is_the_machines(tmp_path: Path) -> None:
    rows = _rows(tmp_path, "student,problem,points,reason\n")
    grades = grades_csv(rows, PROBLEMS)
    assert "late_penalty" not in grades.splitlines()[0]
    assert {who: row["total"] for who, row in _csv(grades).items()}["000103"] == "1"


@pytest.mark.parametrize(
    ("submitted", "penalty", "total"),
    [(DUE, 0.0, 1.0), (DUE + timedelta(minutes=10), 0.0, 1.0), (DUE + timedelta(minutes=11), 0.5, 0.5),
     (DUE + timedelta(days=1, seconds=1), 1.0, 0.0), (DUE + timedelta(days=9), 1.0, 0.0)],
    ids=["at-the-due-time", "end-of-grace", "past-grace", "two-days", "capped-and-floored-at-zero"],
)  # fmt: skip
def test_the_penalty_comes_off_the_total_never_a_problem(
    tmp_path: Path, submitted: object, penalty: float, total: float
) -> None:
    rows = _rows(tmp_path, "student,problem,points,reason\n", late=POLICY, submitted_at={"003100": submitted})
    grade = next(row.grade for row in rows if row.member.identity == "003100")
    assert (grade.late_penalty, grade.total, grade.scores, grade.machine_total) == (
        penalty, total, {"random_blackjack": 1.0, "car": 0.0}, 1.0,
    )  # fmt: skip


def test_an_extension_moves_the_due_time_for_that_student_only(tmp_path: Path) -> None:
    policy = POLICY.model_copy(update={"extensions": {"000103": LATE + timedelta(hours=1)}})
    rows = _rows(tmp_path, "student,problem,points,reason\n", late=policy)
    grade = next(row.grade for row in rows if row.member.identity == "000103")
    assert (grade.late, grade.late_penalty, grade.total) == (False, 0.0, 1.0)


def test_a_roster_student_without_a_submission_can_be_given_a_total() -> None:
    decisions = _decisions("student,problem,points,reason\nzoe,total,1.5,oral exam instead\n", ["zoe"])
    grade = final_grade("zoe", None, None, decisions)
    assert (grade.total, grade.max_score, grade.notes) == (
        1.5, 2.0, ("total overridden to 1.5 (machine: nothing graded): oral exam instead",),
    )  # fmt: skip


def test_the_class_report_shows_overrides_penalties_and_extensions_as_such(tmp_path: Path) -> None:
    from grader.classroom.report import render_class_html, summarise
    from grader.classroom.report.from_batch import entries_from_rows

    policy = POLICY.model_copy(update={"extensions": {"003101": DUE + timedelta(days=2)}})
    text = OVERRIDES + "003101,car,1,<script>alert(1)</script>\n"
    rows = _rows(tmp_path, text, late=policy, submitted_at={"000102": DUE + timedelta(hours=2)})
    summary = summarise(entries_from_rows(rows, tmp_path / "out", tmp_path / "class.html"))
    by_identity = {row.identity: row for row in summary.entries}
    assert (summary.overridden, summary.extended) == (["000101", "000103", "003100", "003101"], ["003101"])
    assert [(o.problem, o.points, o.machine) for o in by_identity["000103"].overrides] == [
        ("total", 2.0, 1.0)
    ]
    assert (by_identity["000102"].score, by_identity["000102"].machine_score) == (0.5, 1.0)
    assert by_identity["000102"].late_penalty == 0.5
    assert by_identity["003101"].extended_to == "2026-03-03T23:59:00+00:00"
    assert summary.scores.mean == pytest.approx((2 + 2 + 1.5 + 0.5 + 2 + 1) / 6)
    page = render_class_html(
        entries_from_rows(rows, tmp_path / "out", tmp_path / "class.html"), summary=summary
    )
    assert "<script>alert" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    assert "(machine: 1)" in page and "(late: −0.5)" in page and "(due 2026-03-03T23:59:00+00:00)" in page
