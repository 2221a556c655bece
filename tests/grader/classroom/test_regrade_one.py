"""Regrading some students of a graded class: exactly their files are graded, every other report is taken as
it is (never graded, never rewritten), and every other row of grades.csv keeps its bytes."""

from __future__ import annotations

import csv
from pathlib import Path

from grader.batch import grade_many
from grader.classroom import discover
from grader.classroom.output import ClassGradebook
from grader.plan import GradingPlan

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
