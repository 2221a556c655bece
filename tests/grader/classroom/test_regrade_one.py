"""Regrading some students of a graded class: exactly their files are graded, every other report is taken as
it is (never graded, never rewritten), and every other row of grades.csv keeps its bytes."""

from __future__ import annotations

import csv
from pathlib import Path

from grader.classroom import discover
from grader.classroom.decisions import Decisions
from grader.classroom.late import LatePolicy
from grader.classroom.output import ClassGradebook
from grader.classroom.overrides import check_overrides, parse_overrides
from grader.grading.batch import grade_many
from grader.grading.plan import GradingPlan
from grader.lab.assignment import load_config
from grader.render.html import render_html
from grader.render.text import render_text
from grader.report import Report

from .downloads import BUILDERS, DUE
from .test_class_batch import ONLY, RULE, FakeExecutor


def _grade(path: Path, out: Path, executor: FakeExecutor, regrade: set[str] | None = None) -> None:
    download = discover(path, rule=RULE, scratch=out.parent / f"scratch-{len(executor.asked)}", due=DUE)
    identities = {s.graded_file.path: s.identity for s in download.submissions if s.graded_file}
    plan = GradingPlan.load(None, ONLY)
    chosen = None if regrade is None else {p for p, who in identities.items() if who in regrade}
    gradebook = ClassGradebook(download, identities, plan.problems)
    grade_many(
        list(identities), out, seed=5, only=ONLY, executor=executor, names=identities, gradebook=gradebook,
        regrade=chosen,
    )  # fmt: skip


def test_regrading_one_student_changes_only_their_report_and_row(tmp_path: Path) -> None:
    expected = BUILDERS["plain"](tmp_path / "download", 3)
    out = tmp_path / "out"
    executor = FakeExecutor()
    _grade(expected.path, out, executor)
    before = {path.name: path.read_bytes() for path in out.iterdir()}
    stale = out / "student001.json"
    stale.write_bytes(stale.read_bytes().replace(b'"grader_version": "', b'"grader_version": "0.0.0-old'))
    before[stale.name] = stale.read_bytes()
    (expected.path / "student000" / "opengym.py").write_bytes(b"def random_blackjack(n):\n    return 0\n")
    _grade(expected.path, out, executor, regrade={"student000"})
    assert [path.parent.name for path in executor.asked[-1]] == ["student000"]
    after = {path.name: path.read_bytes() for path in out.iterdir()}
    changed = sorted(name for name in after if after[name] != before.get(name))
    assert changed == ["grades.csv", "student000.json"], "student001's stale report was not regraded"
    rows_before = before["grades.csv"].decode().splitlines()
    rows_after = after["grades.csv"].decode().splitlines()
    assert [row for row in rows_after if row not in rows_before] == [
        row for row in rows_after if row.startswith("student000,")
    ]
    totals = {row["student"]: row["total"] for row in csv.DictReader(rows_after)}
    assert (totals["student000"], totals["student002"]) == ("0", "1")


def _decided(
    path: Path, out: Path, executor: FakeExecutor, overrides: str, regrade: set[str] | None = None
) -> None:
    download = discover(path, rule=RULE, scratch=out.parent / f"scratch-{len(executor.asked)}", due=DUE)
    identities = {s.graded_file.path: s.identity for s in download.submissions if s.graded_file}
    plan = GradingPlan.load(None, ONLY)
    students = [m.identity for s in download.submissions for m in s.members]
    maxima = {"random_blackjack": 1.0}
    checked = check_overrides(
        parse_overrides(overrides.encode(), where="o.csv"), students=students, maxima=maxima, where="o.csv"
    )
    policy = LatePolicy(due=DUE, penalty_per_day=0.5)
    gradebook = ClassGradebook(
        download,
        identities,
        plan.problems,
        decisions=Decisions(overrides=checked, late=policy, maxima=maxima),
    )
    chosen = None if regrade is None else {p for p, who in identities.items() if who in regrade}
    grade_many(
        list(identities), out, seed=5, only=ONLY, executor=executor, names=identities, gradebook=gradebook,
        regrade=chosen,
    )  # fmt: skip


def test_the_students_report_holds_the_override_and_penalty_through_a_regrade_of_another(
    tmp_path: Path,
) -> None:
    expected = BUILDERS["nbgrader"](tmp_path / "download", 2)
    out = tmp_path / "out"
    executor = FakeExecutor()
    overrides = "student,problem,points,reason\n00000,random_blackjack,0.5,<b>copied</b> from the slides\n"
    _decided(expected.path, out, executor, overrides)
    report = Report.model_validate_json((out / "00000.json").read_text(encoding="utf-8"))
    assert [(d.student, [(o.problem, o.points, o.machine) for o in d.overrides], d.final_score)
            for d in report.instructor] == [("00000", [("random_blackjack", 0.5, 1.0)], 0.5)]  # fmt: skip
    late = Report.model_validate_json((out / "late01.json").read_text(encoding="utf-8"))
    assert [(d.late_penalty, d.final_score) for d in late.instructor] == [(0.5, 0.5)]
    on_time = (out / "00001.json").read_text(encoding="utf-8")
    assert '"instructor"' not in on_time, "a report nothing was decided for keeps its bytes"
    assert render_text(report).splitlines()[4:6] == [
        "Your instructor set random_blackjack to 0.5 (the grader gave 1): <b>copied</b> from the slides",
        "Final score: 0.5 / 1",
    ]
    page = render_html(report, load_config(), figures={})
    assert "&lt;b&gt;copied&lt;/b&gt; from the slides" in page and "<b>copied" not in page
    before = {path.name: path.read_bytes() for path in out.iterdir()}
    _decided(expected.path, out, executor, overrides)
    assert len(executor.asked) == 1, "a full re-run reuses every report"
    _decided(expected.path, out, executor, overrides, regrade={"00001"})
    after = {path.name: path.read_bytes() for path in out.iterdir()}
    assert [path.parent.parent.name for path in executor.asked[-1]] == ["00001"]
    assert after == before, "the regraded student's bytes are the same again; every decision is kept"
