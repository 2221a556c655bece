"""Overrides files: honest files read exactly, hostile ones (formulas, strangers, duplicates, points out of
range, no reason, too large) refused with every fault and its line, nothing neutralised away."""

from __future__ import annotations

import pytest

from grader.classroom.errors import OverridesError
from grader.classroom.overrides import (
    MAX_OVERRIDES_BYTES,
    Override,
    check_overrides,
    parse_overrides,
)

STUDENTS = ("alice", "bob", "0042")
MAXIMA = {"random_blackjack": 1.0, "car": 1.0, "find_qvalues": 0.0}


def _read(text: str) -> dict[str, dict[str, Override]]:
    rows = parse_overrides(text.encode("utf-8"), where="overrides.csv")
    found = check_overrides(rows, students=STUDENTS, maxima=MAXIMA, where="overrides.csv")
    return {student: dict(cells) for student, cells in found.by_student.items()}


def test_an_honest_file_is_read_exactly() -> None:
    found = _read(
        "\ufeffStudent,Problem,Points,Reason,name\r\n"
        "alice,car,1,ran out of time on the cluster; checked by hand,Alice\r\n"
        '0042,total,1.5,"excused, see email",\r\n'
        "\r\n"
        "bob,random_blackjack,0.5,partial,\r\n"
    )
    assert found == {
        "alice": {"car": Override("alice", "car", 1.0, "ran out of time on the cluster; checked by hand", 2)},
        "0042": {"total": Override("0042", "total", 1.5, "excused, see email", 3)},
        "bob": {"random_blackjack": Override("bob", "random_blackjack", 0.5, "partial", 5)},
    }


def test_a_formula_in_a_reason_is_kept_as_text_for_the_outputs_to_neutralise() -> None:
    found = _read('student,problem,points,reason\nalice,car,1,"=HYPERLINK(""http://x"",""y"")"\n')
    assert found["alice"]["car"].reason == '=HYPERLINK("http://x","y")'


@pytest.mark.parametrize(
    ("rows", "fault"),
    [
        ("=cmd|' /C calc'!A0,car,1,x", "line 2: \"=cmd|' /C calc'!A0\" is nobody in this class: write the student as grades.csv's student column names them"),  # noqa: E501
        ("mallory,car,1,x", "line 2: 'mallory' is nobody in this class: write the student as grades.csv's student column names them"),  # noqa: E501
        ("42,car,1,x", "line 2: '42' is nobody in this class: write the student as grades.csv's student column names them"),  # noqa: E501
        ("alice,cartpol,1,x", "line 2: unknown problem 'cartpol': expected one of random_blackjack, car, find_qvalues, total"),  # noqa: E501
        ("alice,car,1.5,x", "line 2: 1.5 points for car of 'alice' is outside 0..1: car is worth 1"),
        ("alice,car,-1,x", "line 2: -1 points for car of 'alice' is outside 0..1: car is worth 1"),
        ("alice,total,2.01,x", "line 2: 2.01 points for total of 'alice' is outside 0..2: total is worth 2"),
        ("alice,find_qvalues,0.5,x", "line 2: 0.5 points for find_qvalues of 'alice' is outside 0..0: find_qvalues is worth 0"),  # noqa: E501
    ],
    ids=["formula-student", "stranger", "leading-zeros-differ", "unknown-problem", "over-max", "negative",
         "total-over-max", "unscored-problem"],
)  # fmt: skip
def test_rows_the_class_does_not_have_are_refused_with_their_line(rows: str, fault: str) -> None:
    with pytest.raises(OverridesError) as raised:
        _read(f"student,problem,points,reason\n{rows}\n")
    assert str(raised.value).splitlines() == [
        "overrides.csv: refused, nothing was written:",
        f"  {fault}",
        "Correct these rows and run the command again.",
    ]


@pytest.mark.parametrize(
    ("rows", "fault"),
    [
        ("alice,car,1,x\nalice,car,0,y", "line 3: 'car' of 'alice' is overridden again (first on line 2): keep one row"),  # noqa: E501
        ("alice,total,1,x\nalice,car,0,y", "line 3: 'alice' has a total override (line 2) and a problem override (line 3): a total decides the whole grade, so keep either the total or the problems"),  # noqa: E501
        ("alice,car,=1+1,x", "line 2: points '=1+1' for 'alice' is not a number: write e.g. 1 or 0.5"),
        ("alice,car,nan,x", "line 2: points 'nan' for 'alice' is not a number: write e.g. 1 or 0.5"),
        ("alice,car,1,", "line 2: no reason for 'car' of 'alice': say why"),
        (",car,1,x", "line 2: no student"),
        ("alice,,1,x", "line 2: no problem for 'alice': expected a problem id or total"),
        ("ali\x1b]0;owned\x07ce,car,x,y", "line 2: points 'x' for 'ali\ufffd]0;owned\ufffdce' is not a number: write e.g. 1 or 0.5"),  # noqa: E501
    ],
    ids=["duplicate", "total-and-problem", "formula-points", "nan-points", "no-reason", "no-student",
         "no-problem", "terminal-escape-shown-inert"],
)  # fmt: skip
def test_a_malformed_row_is_refused_before_the_class_is_looked_at(rows: str, fault: str) -> None:
    with pytest.raises(OverridesError) as raised:
        parse_overrides(f"student,problem,points,reason\n{rows}\n".encode(), where="overrides.csv")
    assert str(raised.value).splitlines()[1] == f"  {fault}"


def test_every_fault_is_listed_and_many_are_counted() -> None:
    text = "student,problem,points,reason\n" + "".join(f"s{n},car,1,x\n" for n in range(25))
    with pytest.raises(OverridesError) as raised:
        _read(text)
    lines = str(raised.value).splitlines()
    assert (len(lines), lines[-2]) == (1 + 20 + 1 + 1, "  ... and 5 more")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"", "overrides.csv is empty: expected a header student,problem,points,reason and a row per override"),  # noqa: E501
        (b"who,what\nalice,car\n", "overrides.csv has no column student, problem, points, reason: expected the header student,problem,points,reason, found who,what"),  # noqa: E501
        (b"student,problem,points,reason\nal\xffce,car,1,x\n", "overrides.csv is not UTF-8 text (byte 32): save it as CSV UTF-8 with the columns student,problem,points,reason"),  # noqa: E501
        (b"x" * (MAX_OVERRIDES_BYTES + 1), f"overrides.csv is {MAX_OVERRIDES_BYTES + 1:,} bytes; an overrides file is at most {MAX_OVERRIDES_BYTES:,}: pass the CSV of student,problem,points,reason rows"),  # noqa: E501
    ],
    ids=["empty", "wrong-header", "not-utf8", "too-large"],
)  # fmt: skip
def test_a_file_that_is_not_an_overrides_csv_says_what_was_expected(data: bytes, message: str) -> None:
    with pytest.raises(OverridesError) as raised:
        parse_overrides(data, where="overrides.csv")
    assert str(raised.value) == message
