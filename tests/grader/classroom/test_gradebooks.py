"""Gradebooks from a class's rows: grades.csv, Canvas (accepted by a re-implementation of its importer),
Gradescope, GitHub Classroom; every cell a spreadsheet would evaluate is neutralised; rosters join."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import pytest

from grader.classroom import GradedFileRule, discover
from grader.classroom.errors import GradebookError, RosterError
from grader.classroom.gradebooks import (
    Assignment,
    canvas_csv,
    class_rows,
    github_classroom_csv,
    grades_csv,
    gradescope_csv,
)
from grader.classroom.roster import parse_roster, read_roster
from grader.render.neutral import safe_cell
from grader.report import ProblemResult, Report

from .canvas_import import CanvasImportError, canvas_import
from .downloads import BUILDERS, DUE

PROBLEMS = ("random_blackjack", "car")
RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))


def _report(identity: str, score: float) -> Report:
    return Report(
        submission=identity,
        sha256="ab" * 32,
        seed=42,
        gymnasium_version="1.4.0",
        grader_version="0.1.0",
        score=score,
        max_score=2.0,
        problems=[
            ProblemResult(
                id=problem, title=problem, status="passed", score=score / 2, max_score=1.0, feedback=""
            )
            for problem in PROBLEMS
        ],
    )


def _graded(layout: str, tmp_path: Path):  # type: ignore[no-untyped-def]
    expected = BUILDERS[layout](tmp_path / "download", 3)
    download = discover(expected.path, rule=RULE, scratch=tmp_path / "scratch", due=DUE)
    reports = {s.identity: _report(s.identity, 2.0) for s in download.submissions if s.graded_file}
    return expected, download, reports


def _csv(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


@pytest.mark.parametrize(
    ("value", "cell"),
    [("=1+2", "'=1+2"), ("+cmd", "'+cmd"), ("-2+3", "'-2+3"), ("@SUM(A1)", "'@SUM(A1)"), ("\tx", "'\tx"),
     ("\rx", "'\ufffdx"), ("alice", "alice"), ("0042", "0042"), (1.5, "1.5"), (None, ""),
     (" =1+2", "' =1+2"), ("\u3000 \u00a0@x", "'\u3000 \u00a0@x"),
     ("\uff1dcmd|' /C calc'!A0", "'\uff1dcmd|' /C calc'!A0"),
     ("\ufe66x", "'\ufe66x"), ("\uff0b1", "'\uff0b1"), ("\uff0d1", "'\uff0d1"),
     ("\uff20SUM(A1)", "'\uff20SUM(A1)"),
     ("\u200b=1", "'\u200b=1"), ("a =1", "a =1"), ("  ", "  "), ("Zoë Ng", "Zoë Ng"),
     ("ali\x1b]0;owned\x07ce", "ali\ufffd]0;owned\ufffdce"), ("\u202eecila", "\ufffdecila"),
     ("two\nlines\tand tab", "two\nlines\tand tab")],
    ids=["equals", "plus", "minus", "at", "tab", "cr", "plain", "leading-zeros", "number", "none",
         "space-then-equals", "wide-spaces-then-at", "fullwidth-equals", "small-equals", "fullwidth-plus",
         "fullwidth-minus", "fullwidth-at", "zero-width-then-equals", "equals-inside", "blank",
         "unicode-name", "terminal-escape", "rtl-override", "newline-and-tab-kept"],
)  # fmt: skip
def test_cells_a_spreadsheet_would_evaluate_are_neutralised(value: object, cell: str) -> None:
    assert safe_cell(value) == cell


@pytest.mark.parametrize("layout", list(BUILDERS), ids=list(BUILDERS))
def test_grades_csv_has_a_row_per_student_under_their_identity(layout: str, tmp_path: Path) -> None:
    expected, download, reports = _graded(layout, tmp_path)
    rows = _csv(grades_csv(class_rows(download, reports), PROBLEMS))
    members = sorted(m.identity for s in download.submissions for m in s.members)
    assert [row["student"].lstrip("'") for row in rows] == members
    assert len(set(members)) == len(members), "each student once"
    for row in rows:
        graded = expected.graded.get(row["student"].lstrip("'"))
        if row["group"]:
            graded = expected.graded[row["group"]]
        assert row["graded_file"].removeprefix("'") == (graded or "")
        assert row["total"] == ("2" if graded else "")
        assert row["seed"] == ("42" if graded else "")
    late = {row["student"] for row in rows if row["late"] == "late"}
    assert late == {m for identity in expected.late for m in identity.split("+")}
    assert list(rows[0])[:10] == [
        "student",
        "name",
        "email",
        "group",
        "graded_file",
        "why",
        "submitted_at",
        "late",
        "sha256",
        "seed",
    ]


def test_a_file_named_like_a_formula_is_text_in_grades_csv(tmp_path: Path) -> None:
    _, download, reports = _graded("plain", tmp_path)
    text = grades_csv(class_rows(download, reports), PROBLEMS)
    assert "\r\n'=1+2,," in text and "\r\n=1+2" not in text
    assert "\r\n0042," in text, "ids keep their leading zeros"


def test_gradescope_group_counts_for_each_member(tmp_path: Path) -> None:
    _, download, reports = _graded("gradescope", tmp_path)
    rows = _csv(gradescope_csv(class_rows(download, reports), PROBLEMS))
    by_sid = {row["SID"]: row for row in rows}
    assert by_sid["000101"]["Total Score"] == by_sid["000102"]["Total Score"] == "2"
    assert (by_sid["000101"]["Name"], by_sid["000101"]["Email"]) == ("Ada Lovelace", "ada@uni.edu")
    assert by_sid["000105"]["Status"] == "Missing"
    assert list(rows[0]) == ["Name", "SID", "Email", "Total Score", "Max Points", "Status", *PROBLEMS]


def test_canvas_csv_is_accepted_by_canvas_import_rules(tmp_path: Path) -> None:
    _, download, reports = _graded("canvas", tmp_path)
    text = canvas_csv(class_rows(download, reports), Assignment("OpenGym lab", "777"))
    students = {m.identity for s in download.submissions for m in s.members}
    changes = canvas_import(text, students, {"777": 2.0})
    assert {user for user, _ in changes} == {s.identity for s in download.submissions if s.graded_file}
    assert set(changes.values()) == {2.0}
    assert text.splitlines()[1] == "    Points Possible,,,,,2"
    assert text.splitlines()[0] == "Student,ID,SIS User ID,SIS Login ID,Section,OpenGym lab (777)"


def test_the_canvas_import_rules_refuse_what_canvas_refuses() -> None:
    good = "Student,ID,SIS User ID,SIS Login ID,Section,Lab (7)\r\nAda,1,,,,2\r\n"
    assert canvas_import(good, {"1"}, {"7": 2.0}) == {("1", "7"): 2.0}
    with pytest.raises(CanvasImportError, match="names no assignment id"):
        canvas_import(good.replace("Lab (7)", "Lab"), {"1"}, {"7": 2.0})
    with pytest.raises(CanvasImportError, match="not in the course"):
        canvas_import(good, {"2"}, {"7": 2.0})
    with pytest.raises(CanvasImportError, match="is not a number"):
        canvas_import(good.replace(",2\r\n", ",two\r\n"), {"1"}, {"7": 2.0})
    with pytest.raises(CanvasImportError, match="missing columns"):
        canvas_import(good.replace("Section,", ""), {"1"}, {"7": 2.0})


def test_canvas_csv_needs_the_assignment_id(tmp_path: Path) -> None:
    _, download, reports = _graded("canvas", tmp_path)
    with pytest.raises(GradebookError, match=r"pass --assignment-id ID"):
        canvas_csv(class_rows(download, reports), Assignment("OpenGym lab", ""))


def test_canvas_csv_from_another_layout_uses_the_roster_ids(tmp_path: Path) -> None:
    _, download, reports = _graded("blackboard", tmp_path)
    roster = parse_roster(
        "Student,ID,SIS User ID,SIS Login ID,Section\r\n    Points Possible,,,,\r\n"
        '"Lovelace, Ada",501,S1,a_lovelace,Sec 1\r\n"Brown, Bob",502,S2,bbrown,Sec 2\r\n'
        '"Absent, Al",503,S3,aabsent,Sec 1\r\n'
    )
    rows = class_rows(download, reports, roster)
    text = canvas_csv(rows, Assignment("Lab 1", "88"))
    assert canvas_import(text, {"501", "502", "503"}, {"88": 2.0}) == {("501", "88"): 2.0, ("502", "88"): 2.0}
    lines = list(csv.reader(io.StringIO(text)))
    assert ["Lovelace, Ada", "501", "S1", "a_lovelace", "Sec 1", "2"] in lines
    assert ["Absent, Al", "503", "S3", "aabsent", "Sec 1", ""] in lines


def test_a_roster_names_missing_students_and_strangers(tmp_path: Path) -> None:
    expected, download, reports = _graded("github-classroom", tmp_path)
    roster = read_roster(expected.path.parent / "roster.csv")
    rows = class_rows(download, reports, roster)
    notes = {row.member.identity: row.note for row in rows}
    assert notes["never-submitted"] == "no submission"
    assert notes["team-rocket"] == "not on the roster"
    assert notes["octo-cat0"] == ""
    github = _csv(github_classroom_csv(rows))
    assert github[0] == {
        "github_username": "dancer",
        "roster_identifier": "",
        "points_awarded": "2",
        "points_available": "2",
    }
    by_user = {row["github_username"]: row for row in github}
    assert by_user["octo-cat1"]["roster_identifier"] == "s0001@uni.edu"
    assert by_user["never-submitted"]["points_awarded"] == ""
    grades = _csv(grades_csv(rows, PROBLEMS))
    assert {row["student"]: row["name"] for row in grades}["octo-cat2"] == "Student 2"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "is empty: expected a CSV with a header row"),
        (
            "colour,size\r\nred,2\r\n",
            "has columns colour, size; expected one naming students: id, github_username",
        ),
    ],
    ids=["empty", "no-id-column"],
)
def test_a_roster_without_students_is_refused_with_what_was_expected(text: str, message: str) -> None:
    with pytest.raises(RosterError, match=message):
        parse_roster(text)


def test_a_roster_matches_one_key_per_layout_and_keeps_leading_zeros() -> None:
    roster = parse_roster("Name,Email,Student ID\r\nAda,Ada@Uni.edu,00123\r\n")
    entry = roster.find("00123")
    assert entry is not None and entry.identity == "00123"
    assert roster.find("123") is None
    assert roster.find("Ada", "plain") is None, "only the layout's key column, never the name"
    assert roster.find("ADA@uni.edu", "gradescope") is entry, "Gradescope's email identities match the email"
    assert roster.find("ada@uni.edu", "plain") is entry, "so do folders named by email"
    assert roster.find("ada@uni.edu", "canvas") is None, "a Canvas identity is a user id"


def _folders(root: Path, names: dict[str, bytes]) -> Path:
    for name, source in names.items():
        (root / name).mkdir(parents=True)
        (root / name / "opengym.py").write_bytes(source)
    return root


def _rows_by_identity(download, roster, scores: dict[str, float]):  # type: ignore[no-untyped-def]
    reports = {s.identity: _report(s.identity, scores[s.identity]) for s in download.submissions}
    return {row.member.identity: row for row in class_rows(download, reports, roster)}


@pytest.mark.parametrize(
    ("folder", "claimed"),
    [("\u212aim", False), ("KIM", True)],
    ids=["kelvin-sign-for-a-k", "ascii-case"],
)
def test_a_folder_named_like_a_roster_student_never_gets_their_row(
    tmp_path: Path, folder: str, claimed: bool
) -> None:
    # Hostile: a folder whose name folds onto Kim's must not put a second row with Kim's id into the LMS.
    download = discover(_folders(tmp_path / "class", {"kim": b"x = 1\n", folder: b"x = 2\n"}), rule=RULE)
    roster = parse_roster("ID,Student,SIS Login ID\r\n501,Kim,kim\r\n")
    rows = _rows_by_identity(download, roster, {"kim": 2.0, folder: 0.0})
    assert rows["kim"].roster is not None and rows["kim"].roster.get("id") == "501" and rows["kim"].note == ""
    assert rows[folder].roster is None and rows[folder].refused_claim is claimed
    if claimed:
        assert rows[folder].note == (
            "refused: KIM matches roster student Kim (sis login id kim), whom kim matched first; left out of "
            "every LMS gradebook: rename the folder or correct the roster"
        )
    else:
        assert rows[folder].note == "not on the roster"
    text = canvas_csv(list(rows.values()), Assignment("Lab 1", "88"))
    assert canvas_import(text, {"501"}, {"88": 2.0}) == {("501", "88"): 2.0}, "one row for Kim, Kim's score"
    grades = {row["student"]: row for row in _csv(grades_csv(list(rows.values()), PROBLEMS))}
    assert set(grades) == {"kim", folder}, "grades.csv keeps every submission, with the note"


def test_a_github_username_equal_to_another_students_roster_identifier_claims_nobody(
    tmp_path: Path,
) -> None:
    # Hostile: the GitHub user "alice" is not Alice (her username is alice-gh, "alice" her roster identifier).
    root = tmp_path / "lab-1-submissions"
    download = discover(_folders(root, {"lab-1-alice-gh": b"x = 1\n", "lab-1-alice": b"x = 2\n"}), rule=RULE)
    assert download.layout == "github-classroom"
    roster = parse_roster("identifier,github_username,github_id,name\r\nalice,alice-gh,7,Alice\r\n")
    rows = _rows_by_identity(download, roster, {"alice-gh": 2.0, "alice": 0.0})
    assert rows["alice-gh"].roster is not None and rows["alice-gh"].name == "Alice"
    assert rows["alice"].roster is None and rows["alice"].note == "not on the roster"
    github = _csv(github_classroom_csv(list(rows.values())))
    assert [(row["github_username"], row["roster_identifier"], row["points_awarded"]) for row in github] == [
        ("alice", "", "0"),
        ("alice-gh", "alice", "2"),
    ]


def test_a_second_claim_on_a_roster_row_is_left_out_of_every_lms_gradebook(tmp_path: Path) -> None:
    root = tmp_path / "lab-1-submissions"
    download = discover(_folders(root, {"lab-1-octo": b"x = 1\n", "lab-1-OCTO": b"x = 2\n"}), rule=RULE)
    roster = parse_roster("identifier,github_username,github_id,name\r\ns1,octo,7,Octo\r\n")
    rows = _rows_by_identity(download, roster, {"octo": 2.0, "OCTO": 0.0})
    assert rows["OCTO"].refused_claim and rows["OCTO"].note.startswith(
        "refused: OCTO matches roster student Octo (github_username octo), whom octo matched first"
    )
    github = _csv(github_classroom_csv(list(rows.values())))
    assert [(row["github_username"], row["points_awarded"]) for row in github] == [("octo", "2")]
    gradescope = _csv(gradescope_csv(list(rows.values()), PROBLEMS))
    assert [row["SID"] for row in gradescope] == ["octo"]


def test_a_student_in_two_submissions_gets_one_row_from_the_latest(tmp_path: Path) -> None:
    export = tmp_path / "assignment_1_export"
    for folder in ("submission_1", "submission_2"):
        (export / folder).mkdir(parents=True)
        (export / folder / "opengym.py").write_text("def random_blackjack(n):\n    return 0\n")
    (export / "submission_metadata.yml").write_text(
        "submission_1:\n  :submitters:\n  - :name: Ada\n    :sid: '01'\n  - :name: Bob\n    :sid: '02'\n"
        "  :created_at: 2026-03-01 10:00:00.000000000 +00:00\n"
        "submission_2:\n  :submitters:\n  - :name: Ada\n    :sid: '01'\n"
        "  :created_at: !ruby/object:ActiveSupport::TimeWithZone\n    utc: 2026-03-02 10:00:00 Z\n"
        "  :history: !!python/object/apply:os.system ['echo owned']\n"
    )
    download = discover(tmp_path, rule=RULE)
    assert [s.identity for s in download.submissions] == ["01", "01+02"]
    rows = class_rows(download, {s.identity: _report(s.identity, 1.0) for s in download.submissions})
    assert [(row.member.identity, row.submission.identity if row.submission else None) for row in rows] == [
        ("01", "01"),
        ("02", "01+02"),
    ]
    assert rows[0].note == "also in 01+02: the latest submission counts"


def test_canvas_text_entries_and_accented_names_are_attributed(tmp_path: Path) -> None:
    (tmp_path / "dl").mkdir()
    for name in [
        "duboischloé_2004_6006_opengym.py",
        "smithjohn_12345_text.html",
        "smithjohn_12345_7_opengym.py",
    ]:
        (tmp_path / "dl" / name).write_text("x = 1\n")
    download = discover(tmp_path / "dl", rule=RULE)
    assert download.layout == "canvas" and download.unattributed == []
    files = {s.identity: sorted(f.original_name for f in s.files) for s in download.submissions}
    assert files == {"12345": ["opengym.py", "text.html"], "2004": ["opengym.py"]}
