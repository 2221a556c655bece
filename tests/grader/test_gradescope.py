"""Gradescope: results.json per its schema, the choice of file, and the autograder zip run for real."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest
from grading_support import CLASSIC_COMPLETE, ROOT, write_config

from grader.cli import main
from grader.gradescope import GradescopeResults, bundle, pick_submission, results
from grader.problems import PROBLEM_IDS
from grader.report import ProblemResult, Report


def _report(**fields: object) -> Report:
    problems = [
        ProblemResult(id="random_blackjack", title="Problem 1", status="passed", score=1, max_score=1,
                      feedback="fine"),
        ProblemResult(id="cartpole", title="Problem 3", status="timeout", score=0, max_score=1,
                      feedback="too slow", output="hello"),
    ]  # fmt: skip
    values: dict[str, object] = {
        "submission": "opengym.py", "sha256": "0", "seed": 3, "gymnasium_version": "1.4.0",
        "grader_version": "0.1.0", "score": 1.0, "max_score": 2.0, "problems": problems,
        "execution_time": 61.6,
    }  # fmt: skip
    values.update(fields)
    return Report.model_validate(values)


def test_a_report_becomes_one_gradescope_test_per_problem() -> None:
    graded = results(_report())
    data = json.loads(graded.model_dump_json())
    assert (data["score"], data["execution_time"], data["visibility"]) == (1.0, 62, "visible")
    assert [(t["name"], t["number"], t["score"], t["max_score"], t["status"]) for t in data["tests"]] == [
        ("Problem 1", "1", 1.0, 1.0, "passed"),
        ("Problem 3", "2", 0.0, 1.0, "failed"),
    ]
    assert data["tests"][1]["output"] == "timeout: too slow\n\nYour output:\nhello"
    assert data["output"].startswith("gymgrade 0.1.0, gymnasium 1.4.0.")
    assert "seed" not in data["output"], "the grading seed stays held out: resubmissions see the same starts"
    GradescopeResults.model_validate(data)


def test_a_skipped_problem_failed_nothing_and_says_it_was_not_run() -> None:
    skipped = ProblemResult(
        id="find_qvalues",
        title="find_qvalues",
        status="skipped",
        score=0,
        max_score=0,
        feedback="Not run: ...",
    )
    graded = results(_report(problems=[skipped], score=0.0, max_score=0.0))
    (test,) = graded.tests
    assert (test.status, test.score, test.max_score, test.output) == (
        "passed",
        0.0,
        0.0,
        "skipped: Not run: ...",
    )


def test_a_file_that_cannot_be_graded_says_why_in_the_output() -> None:
    graded = results(_report(submission_error="opengym.py is empty: nothing to grade."))
    assert "opengym.py is empty: nothing to grade." in graded.output


@pytest.mark.parametrize(
    ("files", "picked"),
    [
        (["opengym.py"], "opengym.py"),
        (["lab.ipynb", ".ipynb_checkpoints/lab-checkpoint.ipynb"], "lab.ipynb"),
        (["helper.py", "opengym.py", "notes.txt"], "opengym.py"),
        (["a.py", "b.py"], "Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, "
         "ideally named opengym.py; found a.py, b.py. Submit exactly one such file."),
        ([], "Expected one Python file (.py) or Jupyter notebook (.ipynb) with your functions, ideally "
         "named opengym.py; found no .py or .ipynb file. Submit exactly one such file."),
    ],
    ids=["one-file", "notebook-beside-checkpoint", "lab-name-among-several", "ambiguous", "nothing"],
)  # fmt: skip
def test_the_graded_file_is_chosen_or_the_student_told(tmp_path: Path, files: list[str], picked: str) -> None:
    for name in files:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("x = 1\n")
    choice = pick_submission(tmp_path)
    assert (choice.name if isinstance(choice, Path) else choice) == picked


def test_check_prints_valid_gradescope_results(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "opengym.ipynb"
    path.write_text("{not json")
    assert main(["check", str(path), "--format", "gradescope", "--only", "cartpole"]) == 1
    data = json.loads(capsys.readouterr().out)
    GradescopeResults.model_validate(data)
    assert data["score"] == 0 and [test["status"] for test in data["tests"]] == ["failed"]
    assert "opengym.ipynb is not a readable notebook" in data["output"]


@pytest.mark.slow
def test_the_bundle_grades_a_submission_in_a_gradescope_layout(tmp_path: Path) -> None:
    overrides = {problem: {"enabled": False} for problem in PROBLEM_IDS if problem != "random_blackjack"}
    overrides["random_blackjack"] = {"games": 2000}
    config = write_config(tmp_path / "assignment.toml", overrides)
    archive = bundle(tmp_path / "autograder.zip", config=config, seed=7)

    with zipfile.ZipFile(archive) as opened:
        names = set(opened.namelist())
        modes = {info.filename: info.external_attr >> 16 for info in opened.infolist()}
        pyproject = tomllib.loads(opened.read("gymgrade/pyproject.toml").decode())
        opened.extractall(tmp_path / "root" / "source")
    assert {"setup.sh", "run_autograder", "assignment.toml", "gymgrade/grader/acceptance/pytest.ini"} <= names
    assert modes["run_autograder"] & 0o111 and modes["setup.sh"] & 0o111
    assert any(requirement.startswith("gymnasium") for requirement in pyproject["project"]["dependencies"])
    source = tmp_path / "root" / "source"
    subprocess.run(["bash", "-n", str(source / "setup.sh")], check=True)

    submission = tmp_path / "root" / "submission"
    submission.mkdir()
    (submission / "opengym.py").write_bytes(CLASSIC_COMPLETE.read_bytes())
    os.chmod(source / "run_autograder", 0o755)
    environment = {
        **os.environ,
        "GYMGRADE_AUTOGRADER_ROOT": str(tmp_path / "root"),
        "GYMGRADE_COMMAND": f"{sys.executable} -m grader.cli",
        "PYTHONPATH": str(ROOT),
    }
    subprocess.run([str(source / "run_autograder")], env=environment, check=True, timeout=600)

    data = json.loads((tmp_path / "root" / "results" / "results.json").read_text())
    GradescopeResults.model_validate(data)
    assert data["score"] == 1.0
    assert [(test["name"], test["status"]) for test in data["tests"]] == [
        ("Problem 1: random Blackjack", "passed")
    ]
    assert "seed 7" not in data["output"]
