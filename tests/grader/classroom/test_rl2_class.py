"""A class of the second lab (Policy Function Iteration, `--lab rl2`) graded into the gradebooks like a class
of the first: a Canvas zip with `--lab rl2` and a Moodle download without it (detection must choose rl2 for
the class), each with honest 2026 files, typical mistakes, two unmodified templates and a file that is not
Python, through the real sandbox."""

from __future__ import annotations

import csv
import json
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pytest

from grader import cli

ROOT = Path(__file__).resolve().parents[3]
RL2 = ROOT / "submissions" / "rl2"
PROBLEMS = ("value_iteration", "policy_iteration", "run_simulation")
"""Graded here (`--only`): the pure solvers and the played episode; frozen_lake and model_comparison cost
minutes per class and are covered per file by tests/grader/lab/rl2/."""
HONEST = (RL2 / "policy_function_iteration.py").read_bytes()
BROKEN = HONEST.replace(b"def run_simulation(", b"def run_simulation(:", 1)
PASSED = dict.fromkeys(PROBLEMS, "passed")


@dataclass(frozen=True)
class Student:
    """One student of the class: the file handed in, each graded problem's status, and what a failed
    problem's feedback must name."""

    name: str
    data: bytes
    status: dict[str, str]
    feedback: dict[str, str]


def _mistake(name: str, problem: str, named: str) -> tuple[bytes, dict[str, str], dict[str, str]]:
    return (RL2 / "mistakes" / f"{name}.py").read_bytes(), PASSED | {problem: "failed"}, {problem: named}


STUDENTS = (
    Student("Ada Lovelace", HONEST, PASSED, {}),
    Student("Bob Brown", (RL2 / "honest_value_iteration_in_place.py").read_bytes(), PASSED, {}),
    Student("Carol King", *_mistake("value_iteration_ignores_beta", "value_iteration", "beta ignored")),
    Student("Dan Ng", *_mistake("value_iteration_first_outcome", "value_iteration", "first outcome only")),
    Student(
        "Erin Hale", *_mistake("run_simulation_no_discount", "run_simulation", "never applied the discount")
    ),
    Student("Fay Wu", (RL2 / "templates" / "v2026.py").read_bytes(), dict.fromkeys(PROBLEMS, "missing"), {}),
    Student("Gus Roy", (RL2 / "templates" / "v2026.py").read_bytes(), dict.fromkeys(PROBLEMS, "missing"), {}),
    Student("Hal Cho", BROKEN, dict.fromkeys(PROBLEMS, "error"), {}),
)
TEMPLATE_PAIR = {"Fay Wu", "Gus Roy"}
FILE = "policy_function_iteration.py"


def _canvas(root: Path) -> tuple[Path, dict[str, Student]]:
    """Canvas "Download Submissions": ``{name}_{user id}_{attachment id}_{file}`` in one zip."""
    root.mkdir(parents=True)
    path = root / "submissions.zip"
    identities: dict[str, Student] = {}
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as bundle:
        for number, student in enumerate(STUDENTS):
            user = str(3000 + number)
            login = student.name.replace(" ", "").lower()
            bundle.writestr(f"{login}_{user}_{7000 + number}_{FILE}", student.data)
            identities[user] = student
    return path, identities


def _moodle(root: Path) -> tuple[Path, dict[str, Student]]:
    """Moodle "Download all submissions": a folder per participant."""
    folder = root / "moodle"
    identities: dict[str, Student] = {}
    for number, student in enumerate(STUDENTS):
        participant = str(91000 + number)
        target = folder / f"{student.name}_{participant}_assignsubmission_file_" / FILE
        target.parent.mkdir(parents=True)
        target.write_bytes(student.data)
        identities[participant] = student
    return folder, identities


def _rows(path: Path) -> list[dict[str, str]]:
    return list(csv.DictReader(path.open(encoding="utf-8", newline="")))


@pytest.mark.slow  # two classes of eight graded through the sandbox (about a minute)
@pytest.mark.parametrize(
    ("layout", "lab"),
    [("canvas", ["--lab", "rl2"]), ("moodle", [])],
    ids=["canvas-lab-rl2", "moodle-detected"],
)
def test_a_class_of_the_second_lab_grades_into_every_gradebook(
    layout: str, lab: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    download, identities = (_canvas if layout == "canvas" else _moodle)(tmp_path / "download")
    out = tmp_path / "out"
    page = tmp_path / "class.html"
    argv = ["grade", str(download), "--out", str(out), *lab, "--only", ",".join(PROBLEMS), "--seed", "7"]
    argv += ["--gradebook", "canvas", "--gradebook", "gradescope", "--gradebook", "github-classroom"]
    argv += ["--assignment-id", "88", "--html", str(page), "--similarity", "--allow-weak-isolation"]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert "Lab: rl2 (Policy Function Iteration / Reinforcement Learning 2)." in err
    assert "Edition: v2026 (" in err
    students = sorted(identities)

    # Every gradebook the first lab writes: a row per student, the rl2 problem ids as columns where it has
    # them.
    grades = _rows(out / "grades.csv")
    assert [row["student"] for row in grades] == students
    header = list(grades[0])
    assert header[header.index("seed") + 1 : header.index("total")] == list(PROBLEMS)
    gradescope = _rows(out / "gradescope.csv")
    assert sorted(row["SID"] for row in gradescope) == students
    assert list(gradescope[0])[-len(PROBLEMS) :] == list(PROBLEMS)
    assert len(_rows(out / "github-classroom.csv")) == len(students)
    canvas = list(csv.reader((out / "canvas.csv").open(encoding="utf-8", newline="")))
    assert canvas[1][0] == "    Points Possible"
    if layout == "canvas":
        assert sorted(row[1] for row in canvas[2:]) == students
    else:  # Moodle's participant ids are not Canvas user ids: left out, and said so
        assert len(canvas) == 2 and "pass --roster with a Canvas gradebook export" in err

    # Each student's statuses, in their report and in the gradebook's scores.
    for row in grades:
        student = identities[row["student"]]
        report = json.loads((out / f"{row['student']}.json").read_text(encoding="utf-8"))
        assert (report["lab"], report["edition"]) == ("rl2", "v2026")
        results = {problem["id"]: problem for problem in report["problems"]}
        assert {problem: results[problem]["status"] for problem in PROBLEMS} == student.status, student.name
        for problem, named in student.feedback.items():
            assert named in results[problem]["feedback"], (student.name, results[problem]["feedback"])
        assert {problem: row[problem] for problem in PROBLEMS} == {
            problem: "1" if status == "passed" else "0" for problem, status in student.status.items()
        }, student.name
        if student.data is BROKEN:
            assert "is not valid Python" in report["submission_error"]
            assert "is not valid Python" in row["note"]
        else:
            assert report["submission_error"] is None and row["note"] == ""

    # The class page and its summary name the lab and the edition.
    summary = json.loads((tmp_path / "class.json").read_text(encoding="utf-8"))
    assert summary["lab"].startswith("rl2 (") and summary["edition"].startswith("v2026 (")
    assert sorted(entry["identity"] for entry in summary["entries"]) == students
    assert [problem["id"] for problem in summary["problems"]] == list(PROBLEMS)
    html = page.read_text(encoding="utf-8")
    assert "rl2 (Policy Function Iteration / Reinforcement Learning 2)" in html and "v2026 (" in html

    # Similarity: the template is discounted, so the two who handed it in unmodified are not a pair; the
    # file that is not Python is left out and said so.
    similarity = json.loads((out / "similarity.json").read_text(encoding="utf-8"))
    by_name = {identity: student.name for identity, student in identities.items()}
    compared = {by_name[identity] for identity in similarity["students"]}
    assert compared >= TEMPLATE_PAIR
    pairs = [{by_name[pair["a"]], by_name[pair["b"]]} for pair in similarity["pairs"]]
    assert TEMPLATE_PAIR not in pairs, similarity["pairs"]
    assert not any(pair & TEMPLATE_PAIR for pair in pairs), "a bare template shares nothing beyond itself"
    assert {"value_iteration", "policy_iteration", "run_simulation"} <= set(similarity["template_functions"])
    assert [by_name[file["identity"]] for file in similarity["unreadable"]] == ["Hal Cho"]
    assert {"Ada Lovelace", "Carol King"} in pairs, "near-copies of one file are still flagged"
