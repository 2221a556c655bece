"""The class report of a `gymgrade grade` batch: entries from its reports, and `--html` end to end."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from grader import cli
from grader.classroom.report.from_batch import page_clash_of_reports


@pytest.mark.slow  # a grading through the sandbox
def test_grade_with_html_writes_the_class_page_and_its_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    (inputs / "alice.py").write_bytes(b"")
    (inputs / "bob.py").write_bytes(b"def car(:\n")
    for name in ("carol", "dave"):
        (inputs / f"{name}.py").write_text(
            "def car():\n    raise ValueError('no car yet')\n", encoding="utf-8"
        )
    out, page = tmp_path / "out", tmp_path / "class.html"
    assert (
        cli.main(
            ["grade", str(inputs), "--out", str(out), "--only", "car", "--seed", "3", "--html", str(page)]
        )
        == 0
    )
    assert (
        f"Wrote the class report {page} and its summary {tmp_path / 'class.json'}." in capsys.readouterr().err
    )
    summary = json.loads((tmp_path / "class.json").read_text(encoding="utf-8"))
    assert (summary["students"], summary["graded"]) == (4, 2)
    assert [row["identity"] for row in summary["submission_errors"]] == ["alice", "bob"]
    assert [(row["problem"], row["status"], row["identities"]) for row in summary["diagnoses"]] == [
        ("car", "error", ["carol", "dave"])
    ]
    assert (
        'raised ValueError: no car yet Traceback (most recent call last): File "/submission/<file>", line #'
        in (summary["diagnoses"][0]["text"])
    ), "the traceback names each student's file; the diagnosis does not"
    assert [row["report_href"] for row in summary["entries"]] == [
        f"out/{name}.json" for name in ("alice", "bob", "carol", "dave")
    ]
    assert all((tmp_path / row["report_href"]).is_file() for row in summary["entries"])
    html = page.read_text(encoding="utf-8")
    assert html.count('href="out/carol.json"') == 2  # under its diagnosis and in the table


def test_grade_refuses_a_json_name_for_the_page_before_grading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "alice.py").write_bytes(b"")
    with pytest.raises(SystemExit):
        cli.main(
            [
                "grade",
                str(tmp_path / "alice.py"),
                "--out",
                str(tmp_path / "out"),
                "--html",
                str(tmp_path / "c.json"),
            ]
        )
    assert "expected an .html file name (the JSON summary is written beside it)" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("page", "clash"),
    [
        ("class.html", None),
        ("out/class.html", "would write {out}/class.json over the report of class"),
        ("out/alice.html", "would write {out}/alice.json over the report of alice"),
        ("out/grades.csv", "would write {out}/grades.csv over the batch's grades.csv"),
        ("out/summary.html", None),
    ],
    ids=["outside", "a-student-named-class", "a-students-name", "the-gradebook", "inside-no-clash"],
)
def test_the_class_page_never_overwrites_a_file_of_the_batch(
    tmp_path: Path, page: str, clash: str | None
) -> None:
    inputs, out = tmp_path / "in", tmp_path / "out"
    reports = {out / "alice.json": "alice", out / "class.json": "class"}
    found = page_clash_of_reports(tmp_path / page, reports, out)
    if clash is None:
        assert found is None
    else:
        assert found is not None and clash.format(out=out, inputs=inputs) in found


def test_grade_refuses_a_page_that_would_overwrite_a_report_before_grading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "class.py").write_bytes(b"")
    out = tmp_path / "out"
    arguments = ["grade", str(tmp_path / "class.py"), "--out", str(out), "--html", str(out / "class.html")]
    assert cli.main(arguments) == cli.EXIT_ERROR
    assert f"would write {out / 'class.json'} over the report of student class; put the page outside" in (
        capsys.readouterr().err
    )
    assert not out.exists()
