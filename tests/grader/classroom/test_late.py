"""The late policy: penalties exactly at the edges (the due time, the grace, a day, the cap, an extension,
an unknown hour), and the [late] table's errors."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import pytest

from grader.classroom.errors import LatePolicyError
from grader.classroom.late import LatePolicy, lateness, read_late_policy
from grader.lab.assignment import load_config

EST = timezone(timedelta(hours=-5))
DUE = datetime(2026, 3, 1, 23, 59, tzinfo=EST)
POLICY = LatePolicy(
    due=DUE,
    penalty_per_day=0.1,
    max_penalty=0.3,
    grace_minutes=15,
    extensions={"alice": DUE + timedelta(days=3)},
)
SECOND = timedelta(seconds=1)
GRACE = timedelta(minutes=15)


@pytest.mark.parametrize(
    ("student", "submitted", "days", "penalty"),
    [
        ("bob", DUE - timedelta(days=2), 0, 0.0),
        ("bob", DUE, 0, 0.0),
        ("bob", DUE + GRACE, 0, 0.0),
        ("bob", DUE + GRACE + SECOND, 1, 0.7),
        ("bob", DUE + timedelta(days=1), 1, 0.7),
        ("bob", DUE + timedelta(days=1) + SECOND, 2, 1.4),
        ("bob", DUE + timedelta(days=3), 3, 2.1),
        ("bob", DUE + timedelta(days=3) + SECOND, 4, 2.1),
        ("bob", DUE + timedelta(days=40), 40, 2.1),
        ("alice", DUE + timedelta(days=3), 0, 0.0),
        ("alice", DUE + timedelta(days=3) + GRACE + SECOND, 1, 0.7),
        ("bob", datetime(2026, 3, 2, 4, 59, tzinfo=UTC), 0, 0.0),
        ("bob", datetime(2026, 3, 2, 5, 14, 1, tzinfo=UTC), 1, 0.7),
        ("bob", datetime(2026, 3, 1, 23, 59, 0), 0, 0.0),
        ("bob", datetime(2026, 3, 2, 0, 14, 1), 1, 0.7),
    ],
    ids=["early", "at-the-due-time", "at-the-end-of-grace", "a-second-past-grace", "a-day",
         "a-day-and-a-second", "three-days-at-the-cap", "past-the-cap", "forty-days-capped",
         "extension-at-its-due-time", "extension-past-its-grace", "utc-at-the-due-time", "utc-past-grace",
         "no-zone-read-in-the-due-zone", "no-zone-past-grace"],
)  # fmt: skip
def test_the_penalty_at_the_edges(student: str, submitted: datetime, days: int, penalty: float) -> None:
    found = lateness(POLICY, student, submitted_at=submitted, marked_late=None, max_score=7.0)
    assert (found.days, found.penalty) == (days, penalty)
    assert (found.note == "") == (days == 0)


def test_the_note_says_days_times_and_the_cap() -> None:
    found = lateness(POLICY, "bob", submitted_at=DUE + timedelta(days=5), marked_late=None, max_score=7.0)
    assert found.note == (
        "5 days late (submitted 2026-03-06T23:59:00-05:00, due 2026-03-01T23:59:00-05:00): "
        "2.1 points taken (the policy's cap)"
    )


@pytest.mark.parametrize(
    ("student", "marked", "days", "penalty", "note"),
    [
        ("bob", None, 0, 0.0, ""),
        ("bob", False, 0, 0.0, ""),
        ("bob", True, 1, 0.7, "marked late by the download, the hours unknown: charged one day, the least a late mark means; give the time with --submitted-at FILE (or a Canvas submissions CSV) for the policy's count"),  # noqa: E501
        ("alice", True, 0, 0.0, "marked late by the download, but their due time is extended to 2026-03-04T23:59:00-05:00 and the hours are unknown: no penalty taken; give the time with --submitted-at FILE"),  # noqa: E501
    ],
    ids=["unknown", "marked-on-time", "marked-late-hours-unknown", "marked-late-with-extension"],
)  # fmt: skip
def test_a_late_mark_without_hours(
    student: str, marked: bool | None, days: int, penalty: float, note: str
) -> None:
    found = lateness(POLICY, student, submitted_at=None, marked_late=marked, max_score=7.0)
    assert (found.days, found.penalty, found.note) == (days, penalty, note)


def _config(tmp_path: Path, late: str) -> Path:
    bundled = (Path(__file__).resolve().parents[3] / "grader" / "lab" / "assignment.toml").read_text(
        encoding="utf-8"
    )
    path = tmp_path / "assignment.toml"
    path.write_text(bundled + "\n" + late, encoding="utf-8")
    return path


def test_the_late_table_is_read_from_the_configuration_and_changes_no_grading(tmp_path: Path) -> None:
    path = _config(
        tmp_path,
        "[late]\ndue = 2026-03-01T23:59:00-05:00\npenalty_per_day = 0.1\nmax_penalty = 0.3\ngrace_minutes = 15\n"  # noqa: E501
        '[late.extensions]\nalice = "2026-03-04T23:59:00-05:00"\n',
    )
    assert read_late_policy(path) == POLICY
    assert load_config(path).model_dump_json() == load_config(None).model_dump_json()
    assert read_late_policy(None) is None


@pytest.mark.parametrize(
    ("late", "line"),
    [
        ("[late]\ndue = 2026-03-01T23:59:00\npenalty_per_day = 0.1\n", "  late.due: Input should have timezone info (found datetime.datetime(2026, 3, 1, 23, 59))"),  # noqa: E501
        ("[late]\ndue = 2026-03-01T23:59:00Z\npenalty_per_day = 10\n", "  late.penalty_per_day: Input should be less than or equal to 1 (found 10)"),  # noqa: E501
        ("[late]\ndue = 2026-03-01T23:59:00Z\npenalty_per_day = 0.1\ngrace = 5\n", "  late.grace: Extra inputs are not permitted (found 5)"),  # noqa: E501
        ("[late]\ndue = 2026-03-01T23:59:00Z\npenalty_per_day = 0.1\n[late.extensions]\nbob = \"friday\"\n", "  late.extensions.bob: Input should be a valid datetime or date, input is too short (found 'friday')"),  # noqa: E501
    ],
    ids=["due-without-zone", "penalty-over-one", "misspelt-field", "extension-not-a-time"],
)  # fmt: skip
def test_an_invalid_late_table_names_the_field(tmp_path: Path, late: str, line: str) -> None:
    with pytest.raises(LatePolicyError) as raised:
        read_late_policy(_config(tmp_path, late))
    lines = str(raised.value).splitlines()
    assert lines[0].endswith("assignment.toml: invalid [late] table:")
    assert lines[1] == line
