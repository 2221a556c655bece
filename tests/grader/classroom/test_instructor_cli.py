"""`gymgrade grade` with the instructor's last word, the whole command but grading (an instant executor
stands in for the sandbox): overrides and late penalties in every gradebook, the class report and the
student's report; kept across a re-run and a resumed batch; --only-students regrades one student and
leaves every other byte as it was."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

from grader import cli
from grader.classroom import command
from grader.report import Report

from .downloads import BUILDERS, DUE
from .test_class_batch import FakeExecutor, InterruptingExecutor

BUNDLED = Path(__file__).resolve().parents[3] / "grader" / "lab" / "assignment.toml"
LATE = f"""
[late]
due = {DUE.isoformat()}
penalty_per_day = 0.5
max_penalty = 1.0

[late.extensions]
"2004" = "{DUE.replace(day=5).isoformat()}"
"""


def _config(tmp_path: Path) -> Path:
    path = tmp_path / "assignment.toml"
    path.write_text(BUNDLED.read_text(encoding="utf-8") + LATE, encoding="utf-8")
    return path


def _files(out: Path) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(out.iterdir())}


def _rows(path: Path) -> dict[str, dict[str, str]]:
    return {row["student"]: row for row in csv.DictReader(path.open(encoding="utf-8", newline=""))}


@pytest.fixture
def executor(monkeypatch: pytest.MonkeyPatch) -> FakeExecutor:
    fake = FakeExecutor()
    monkeypatch.setattr(command, "find_executor", lambda policy: fake)
    return fake


def test_a_canvas_class_with_overrides_and_a_late_policy(
    tmp_path: Path, executor: FakeExecutor, capsys: pytest.CaptureFixture[str]
) -> None:
    expected = BUILDERS["canvas"](tmp_path / "download", 2)
    overrides = tmp_path / "overrides.csv"
    overrides.write_text(
        "student,problem,points,reason\n1000,random_blackjack,0,=copied from 1001 (see email)\n"
        "2001,total,0.25,academic integrity hearing\n",
        encoding="utf-8",
    )
    times = tmp_path / "times.csv"
    times.write_text("user_id,submitted_at\n2004,2026-03-03T10:00:00Z\n", encoding="utf-8")
    out = tmp_path / "out"
    argv = ["grade", str(expected.path), "--out", str(out), "--only", "random_blackjack", "--seed", "3"]
    argv += ["--config", str(_config(tmp_path)), "--overrides", str(overrides), "--submitted-at", str(times)]
    argv += ["--gradebook", "canvas", "--assignment-id", "9", "--gradebook", "gradescope"]
    argv += ["--gradebook", "github-classroom", "--html", str(tmp_path / "class.html")]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"Overrides: 2 from {overrides} (kept as {out / 'overrides.csv'} for later runs)" in err
    assert (
        "Late policy: due 2026-03-01T23:59:00+00:00, 0.5 of the maximum per day or part of a day, at most 1, 1 extensions"  # noqa: E501
        in err
    )
    grades = _rows(out / "grades.csv")
    decided = {
        who: (row["random_blackjack"], row["late"], row["late_penalty"], row["total"])
        for who, row in grades.items()
    }
    assert decided == {
        "1000": ("0", "on time", "0", "0"),
        "1001": ("1", "on time", "0", "1"),
        "2001": ("1", "on time", "0", "0.25"),
        "2002": ("1", "late", "0.5", "0.5"),
        "2003": ("1", "on time", "0", "1"),
        "2004": ("1", "on time", "0", "1"),
        "2005": ("1", "on time", "0", "1"),
        "2006": ("", "", "0", ""),
    }
    assert (
        grades["1000"]["note"]
        == "random_blackjack overridden to 0 (machine: 1): =copied from 1001 (see email)"
    )
    assert grades["2002"]["note"].startswith(
        "marked late by the download, the hours unknown: charged one day"
    )
    assert grades["2004"]["submitted_at"] == "2026-03-03T10:00:00+00:00"
    canvas = {row[1]: row[5] for row in csv.reader((out / "canvas.csv").open(encoding="utf-8"))}
    assert (canvas["1000"], canvas["2001"], canvas["2002"]) == ("0", "0.25", "0.5")
    gradescope = {
        row["SID"]: row["Total Score"]
        for row in csv.DictReader((out / "gradescope.csv").open(encoding="utf-8"))
    }
    assert (gradescope["1000"], gradescope["2002"]) == ("0", "0.5")
    summary = json.loads((tmp_path / "class.json").read_text(encoding="utf-8"))
    assert (summary["overridden"], summary["extended"]) == (["1000", "2001"], ["2004"])
    report = Report.model_validate_json((out / "1000.json").read_text(encoding="utf-8"))
    assert [(o.problem, o.points, o.machine, o.reason) for d in report.instructor for o in d.overrides] == [
        ("random_blackjack", 0.0, 1.0, "=copied from 1001 (see email)")
    ]
    before = _files(out)
    overrides.unlink()
    times.unlink()
    again = [
        part for part in argv if part not in (str(overrides), str(times), "--overrides", "--submitted-at")
    ]
    assert cli.main(again) == 0
    assert f"Overrides: 2 from {out / 'overrides.csv'} (kept from an earlier run" in capsys.readouterr().err
    assert len(executor.asked) == 1, "the re-run grades nothing"
    assert _files(out) == before, "a re-run without the options keeps every override and time"


def test_overrides_survive_an_interrupted_batch_and_its_resumption(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from grader.grading import batch

    monkeypatch.setattr(batch, "GRADEBOOK_INTERVAL", 3600.0)
    expected = BUILDERS["plain"](tmp_path / "download", 4)
    overrides = tmp_path / "o.csv"
    overrides.write_text("student,problem,points,reason\nstudent003,total,0,plagiarism\n", encoding="utf-8")
    out = tmp_path / "out"
    argv = ["grade", str(expected.path), "--out", str(out), "--only", "random_blackjack", "--seed", "3"]
    monkeypatch.setattr(command, "find_executor", lambda policy: InterruptingExecutor(after=2))
    assert cli.main([*argv, "--overrides", str(overrides)]) == cli.EXIT_INTERRUPTED
    monkeypatch.setattr(command, "find_executor", lambda policy: FakeExecutor())
    assert cli.main(argv) == 0
    grades = _rows(out / "grades.csv")
    assert (grades["student003"]["total"], grades["student002"]["total"]) == ("0", "1")
    assert grades["student003"]["note"] == "total overridden to 0 (machine: 1): plagiarism"


def test_only_students_regrades_one_and_leaves_every_other_byte(
    tmp_path: Path, executor: FakeExecutor, capsys: pytest.CaptureFixture[str]
) -> None:
    expected = BUILDERS["plain"](tmp_path / "download", 3)
    out = tmp_path / "out"
    argv = ["grade", str(expected.path), "--out", str(out), "--only", "random_blackjack"]
    assert cli.main(argv) == 0
    assert cli.main([*argv, "--only-students", "student001", "--seed", "4"]) == cli.EXIT_ERROR
    assert re.search(
        r"was graded with seed \d+, this run grades with 4: pass --seed \d+ or leave out --seed",
        capsys.readouterr().err,
    )
    assert cli.main([*argv, "--only-students", "student001,nobody"]) == cli.EXIT_ERROR
    assert "--only-students names 'nobody', who submitted nothing in this download" in capsys.readouterr().err
    before = _files(out)
    (expected.path / "student001" / "opengym.py").write_bytes(b"def random_blackjack(n):\n    return 0\n")
    (expected.path / "student002" / "opengym.py").write_bytes(b"# changed too, but not asked for\n")
    assert cli.main([*argv, "--only-students", "student001"]) == 0
    assert [path.parent.name for path in executor.asked[-1]] == ["student001"]
    after = _files(out)
    assert sorted(name for name in after if after[name] != before[name]) == ["grades.csv", "student001.json"]
    changed = [
        line for line in after["grades.csv"].splitlines() if line not in before["grades.csv"].splitlines()
    ]
    assert [line.split(b",")[0] for line in changed] == [b"student001"]


def test_only_students_needs_a_graded_class(
    tmp_path: Path, executor: FakeExecutor, capsys: pytest.CaptureFixture[str]
) -> None:
    expected = BUILDERS["plain"](tmp_path / "download", 2)
    argv = ["grade", str(expected.path), "--out", str(tmp_path / "out"), "--only-students", "student000"]
    assert cli.main(argv) == cli.EXIT_ERROR
    assert "nothing is graded there: run without --only-students first" in capsys.readouterr().err
    assert executor.asked == []
